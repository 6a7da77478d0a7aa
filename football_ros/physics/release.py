# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Release conditions and the rigid-body state they start (docs/physics.md sections 1 and 3).

A :class:`Release` is what a user says ("27.4 m/s, 30 deg, 600 rpm, nose 2 deg up"); an
:class:`InitialState` is the rigid-body state it means in ``field``. Both are validated here,
against :data:`LIMITS`, the one table of accepted ranges.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import math
from typing import Any, Mapping

import numpy as np

from . import frames
from .aero import AeroModel
from .presets import BallPreset, get_preset

RPM = 2.0 * math.pi / 60.0
"""rad/s per rev/min."""

MODELS = ('paper', 'full')
MOMENT_CURVES = ('linear', 'sin2delta')

LIMITS: dict[str, tuple[float, float]] = {
    'speed': (1.0, 60.0),  # m/s; the fastest passes and kicks are near 30 m/s
    'elevation_deg': (-80.0, 80.0),  # deg; the velocity frame is undefined for vertical v
    'azimuth_deg': (-180.0, 180.0),  # deg, counter-clockwise from +x seen from above
    'spin_rpm': (-3000.0, 3000.0),  # rev/min, sign = hand
    'alpha0_deg': (-60.0, 60.0),  # deg; moment data exist up to about 50 deg
    'beta0_deg': (-60.0, 60.0),
    'alpha_rate_deg_s': (-3600.0, 3600.0),
    'beta_rate_deg_s': (-3600.0, 3600.0),
    'position_xy': (-10000.0, 10000.0),  # m
    'position_z': (0.0, 1000.0),  # m; the ground is z = 0
    'axis_offset_deg': (0.0, 60.0),  # total angle delta of a full-state release
    'transverse_rate_deg_s': (0.0, 3600.0),
}


STATE_KEYS = (
    'speed',
    'elevation_deg',
    'azimuth_deg',
    'spin_rpm',
    'alpha0_deg',
    'beta0_deg',
    'alpha_rate_deg_s',
    'beta_rate_deg_s',
)
"""The release's numbers that set its state: :func:`release_states`' arguments, in order."""

ERROR_SIGMAS = {
    'speed': 0.5,
    'elevation_deg': 1.0,
    'azimuth_deg': 1.0,
    'spin_rpm': 30.0,
    'alpha0_deg': 1.0,
    'beta0_deg': 1.0,
    'alpha_rate_deg_s': 10.0,
    'beta_rate_deg_s': 10.0,
}
"""Default standard deviations of a thrower's release errors, in each key's units (the Monte
Carlo's spreads and the planner's hit probability)."""

DERIVED_SLACK = 1e-9
"""Round-off allowance (fraction of a range) for quantities derived from a rigid-body state."""


class ReleaseError(ValueError):
    """A release that cannot be flown; the message says why in one sentence."""


def check_range(name: str, value: Any, limits_key: str | None = None, slack: float = 0.0) -> float:
    """
    Return ``value`` as a float if it is a finite number inside ``LIMITS``, else raise.

    ``slack`` widens the range by that fraction of its span (for quantities derived from other
    numbers, whose round-off must not turn an accepted release into a refused one).
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ReleaseError(
            f"'{name}' must be a number, got {type(value).__name__} {_brief(value)}"
        )
    lo, hi = LIMITS[limits_key or name]
    try:
        value = float(value)
    except OverflowError:
        raise ReleaseError(f"'{name}' is outside the accepted range [{lo:g}, {hi:g}]") from None
    if not math.isfinite(value):
        raise ReleaseError(f"'{name}' must be finite, got {value}")
    pad = slack * (hi - lo)
    if not lo - pad <= value <= hi + pad:
        raise ReleaseError(f"'{name}' = {value:g} is outside the accepted range [{lo:g}, {hi:g}]")
    return min(max(value, lo), hi)


def check_choice(name: str, value: Any, choices: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``choices``, else raise ReleaseError naming ``name``."""
    if not isinstance(value, str) or value not in choices:
        raise ReleaseError(f"'{name}' must be one of {', '.join(choices)}, got {_brief(value)}")
    return value


def check_settings(
    ball: Any, ball_params: Any, model: Any, moment: Any, aero: Any
) -> tuple[BallPreset, AeroModel | None]:
    """
    Check a flight's settings (the one check): ball preset and overrides, model, moment, aero.

    Returns the ball with its overrides and the full model's settings (None for the paper's
    model); raises ReleaseError naming the field.
    """
    check_choice('model', model, MODELS)
    check_choice('moment', moment, MOMENT_CURVES)
    if not isinstance(ball, str):
        raise ReleaseError(f"'ball' must be a preset name, got {_brief(ball)}")
    for key, value in (('ball_params', ball_params), ('aero', aero)):
        if not isinstance(value, Mapping):
            raise ReleaseError(f"'{key}' must be a mapping, got {_brief(value)}")
    try:
        preset = get_preset(ball, ball_params)
    except (ValueError, TypeError) as exc:
        raise ReleaseError(str(exc)) from None
    if model != 'full':
        if aero:
            raise ReleaseError("'aero' settings need model: full")
        return preset, None
    try:
        return preset, AeroModel.from_mapping(aero)
    except (ValueError, TypeError) as exc:
        raise ReleaseError(str(exc)) from None


def _brief(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + '...'


def check_position(position: Any) -> tuple[float, float, float]:
    """Validate a release position [x, y, z] in ``field`` [m]."""
    if not isinstance(position, (list, tuple, np.ndarray)) or len(position) != 3:
        raise ReleaseError(
            f"'position' must be a list [x, y, z] of 3 numbers, got {_brief(position)}"
        )
    x = check_range('position[0]', position[0], 'position_xy')
    y = check_range('position[1]', position[1], 'position_xy')
    z = check_range('position[2]', position[2], 'position_z')
    return (x, y, z)


@dataclass(frozen=True)
class InitialState:
    """
    Rigid-body state at release, all in ``field``.

    position [m], velocity [m/s], axis (unit spin axis toward the leading nose),
    transverse_rate (angular velocity perpendicular to the axis) [rad/s], spin [rad/s] about
    +axis (right-hand rule), attitude (x, y, z, w) with body x = axis.
    """

    position: np.ndarray
    velocity: np.ndarray
    axis: np.ndarray
    transverse_rate: np.ndarray
    spin: float
    attitude: np.ndarray

    def angular_velocity(self) -> np.ndarray:
        """Total angular velocity w = w_perp + p s [rad/s] in ``field``."""
        return self.transverse_rate + self.spin * self.axis

    def modified_momentum(self, ball: BallPreset) -> np.ndarray:
        """H = H / I_t = w_perp + (I_s/I_t) p s [rad/s]."""
        return self.transverse_rate + ball.inertia_ratio * self.spin * self.axis

    @staticmethod
    def from_rigid_body(position, velocity, attitude, angular_velocity) -> 'InitialState':
        """
        Build and validate from a full rigid-body state (body x of ``attitude`` = axis).

        Raises ReleaseError for non-finite numbers, a speed, spin, axis offset or transverse
        rate outside LIMITS, or a release that starts on the ground heading down.
        """
        arrays = []
        for name, value, size in (
            ('position', position, 3),
            ('velocity', velocity, 3),
            ('orientation', attitude, 4),
            ('angular velocity', angular_velocity, 3),
        ):
            arr = np.asarray(value, dtype=float).reshape(-1)
            if arr.size != size or not np.all(np.isfinite(arr)):
                raise ReleaseError(f'{name} must be {size} finite numbers, got {list(arr)}')
            arrays.append(arr)
        pos, vel, quat, omega = arrays
        check_position(list(pos))
        check_range('speed', math.hypot(*vel), slack=DERIVED_SLACK)  # hypot: no overflow
        check_range(
            'elevation_deg',
            math.degrees(float(frames.flight_path_angle(vel))),
            slack=DERIVED_SLACK,
        )
        norm = math.hypot(*quat)
        if abs(norm - 1.0) > 1e-3:
            raise ReleaseError(f'orientation must be a unit quaternion, |q| = {norm:.6g}')
        quat = quat / norm
        axis = frames.body_x_axis(quat)
        delta = math.degrees(float(frames.aero_angles(axis, vel)[2]))
        check_range('axis offset from the velocity (deg)', delta, 'axis_offset_deg', DERIVED_SLACK)
        spin = float(np.dot(omega, axis))
        check_range('spin_rpm', spin / RPM, slack=DERIVED_SLACK)
        transverse = omega - spin * axis
        check_range(
            'transverse angular rate (deg/s)',
            math.degrees(math.hypot(*transverse)),
            'transverse_rate_deg_s',
            DERIVED_SLACK,
        )
        if pos[2] <= 0.0 and vel[2] <= 0.0:
            raise ReleaseError('a release on the ground (z = 0) must go up (positive elevation)')
        return InitialState(pos, vel, axis, transverse, spin, quat)


@dataclass(frozen=True)
class Release:
    """
    A release as a user states it. Angles in degrees, speed in m/s, spin in rev/min.

    alpha0_deg/beta0_deg: spin-axis offset from the velocity (angle of attack, sideslip).
    alpha_rate_deg_s/beta_rate_deg_s: rates at which the axis turns relative to ``field``
    (0/0 = "not rotating relative to the field", the paper's default).
    """

    ball: str = 'american'
    speed: float | None = None
    elevation_deg: float | None = None
    azimuth_deg: float = 0.0
    spin_rpm: float | None = None
    alpha0_deg: float = 0.0
    beta0_deg: float = 0.0
    alpha_rate_deg_s: float = 0.0
    beta_rate_deg_s: float = 0.0
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    model: str = 'paper'
    moment: str = 'linear'
    ball_params: Mapping[str, float] = field(default_factory=dict)
    aero: Mapping[str, Any] = field(default_factory=dict)

    FIELDS = (
        'ball',
        *STATE_KEYS,
        'position',
        'model',
        'moment',
        'ball_params',
        'aero',
    )

    def __post_init__(self) -> None:
        preset = self.preset()  # validates ball, ball_params, model, moment and aero
        for name, default in (
            ('speed', preset.speed),
            ('elevation_deg', preset.elevation_deg),
            ('spin_rpm', preset.spin_rpm),
        ):
            value = getattr(self, name)
            object.__setattr__(self, name, check_range(name, default if value is None else value))
        for name in (
            'azimuth_deg',
            'alpha0_deg',
            'beta0_deg',
            'alpha_rate_deg_s',
            'beta_rate_deg_s',
        ):
            object.__setattr__(self, name, check_range(name, getattr(self, name)))
        object.__setattr__(self, 'position', check_position(self.position))
        if self.position[2] <= 0.0 and self.elevation_deg <= 0.0:
            raise ReleaseError('a release on the ground (z = 0) must go up (positive elevation)')
        # The combined limits (total axis offset, transverse rate) of the state it starts: the
        # rules the simulator applies to every flight order, so that one truth decides.
        st = self.initial_state()
        InitialState.from_rigid_body(st.position, st.velocity, st.attitude, st.angular_velocity())

    def aero_model(self) -> AeroModel | None:
        """Return the full model's settings (None for the paper's model)."""
        return self._settings()[1]

    def preset(self) -> BallPreset:
        """Return the ball with ``ball_params`` applied."""
        return self._settings()[0]

    def _settings(self) -> tuple[BallPreset, AeroModel | None]:
        return check_settings(self.ball, self.ball_params, self.model, self.moment, self.aero)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> 'Release':
        """Build from a mapping of the release keys; unknown keys raise ReleaseError."""
        unknown = sorted(set(data) - set(cls.FIELDS))
        if unknown:
            raise ReleaseError(
                f'unknown key(s) {_brief(", ".join(map(repr, unknown)))}; '
                f'known: {", ".join(cls.FIELDS)}'
            )
        kwargs = dict(data)
        for key in ('ball_params', 'aero'):
            if key in kwargs and kwargs[key] is None:
                kwargs[key] = {}
        if 'position' in kwargs:
            kwargs['position'] = check_position(kwargs['position'])
        return cls(**kwargs)

    def to_mapping(self) -> dict[str, Any]:
        """Plain-data form (JSON/YAML-safe)."""
        out = {name: getattr(self, name) for name in self.FIELDS}
        out['position'] = list(self.position)
        out['ball_params'] = dict(self.ball_params)
        out['aero'] = dict(self.aero)
        return out

    def initial_state(self) -> InitialState:
        """Return the rigid-body state in ``field`` this release means (docs/physics.md sec. 1)."""
        return initial_state_of(
            release_states(
                self.speed,
                self.elevation_deg,
                self.azimuth_deg,
                self.spin_rpm,
                self.alpha0_deg,
                self.beta0_deg,
                self.alpha_rate_deg_s,
                self.beta_rate_deg_s,
                np.array(self.position, dtype=float),
            )
        )

    def replace(self, **changes: Any) -> 'Release':
        """Return a validated copy with some fields changed."""
        return dataclasses.replace(self, **changes)


def release_states(
    speed,
    elevation_deg,
    azimuth_deg,
    spin_rpm,
    alpha0_deg,
    beta0_deg,
    alpha_rate_deg_s,
    beta_rate_deg_s,
    position,
) -> dict[str, np.ndarray]:
    """
    Vectorised release -> rigid-body state in ``field`` (arrays broadcast to N releases).

    Returns position, velocity [m/s], axis (unit), transverse_rate [rad/s] (each (N, 3)) and
    spin [rad/s] (N,). The axis is (alpha0, beta0) off the velocity; its rates are relative to
    the field with the velocity frame held at its release value, and w_perp = s x s'.
    """
    arrays = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(x, dtype=float))
            for x in (
                speed,
                elevation_deg,
                azimuth_deg,
                spin_rpm,
                alpha0_deg,
                beta0_deg,
                alpha_rate_deg_s,
                beta_rate_deg_s,
            )
        )
    )
    speed, elev, azim, spin_rpm, alpha, beta, alpha_rate, beta_rate = arrays
    elev, azim, alpha, beta = (np.radians(x) for x in (elev, azim, alpha, beta))
    velocity = frames.direction(speed, elev, azim)
    axis = frames.axis_from_aero_angles(alpha, beta, velocity)
    # d axis / d alpha and d axis / d beta, in the velocity frame held at its release value.
    ca, sa, cb, sb = np.cos(alpha), np.sin(alpha), np.cos(beta), np.sin(beta)
    d_alpha = np.stack([-cb * sa, cb * ca, np.zeros_like(ca)], axis=-1)
    d_beta = np.stack([-sb * ca, -sb * sa, cb], axis=-1)
    axis_rate = frames.from_velocity_frame(
        np.radians(alpha_rate)[:, None] * d_alpha + np.radians(beta_rate)[:, None] * d_beta,
        velocity,
    )
    position = np.broadcast_to(np.asarray(position, dtype=float), velocity.shape).copy()
    return {
        'position': position,
        'velocity': velocity,
        'axis': axis,
        'transverse_rate': np.cross(axis, axis_rate),
        'spin': spin_rpm * RPM,
    }


def initial_state_of(states: dict[str, np.ndarray], i: int = 0) -> InitialState:
    """Return release ``i`` of :func:`release_states` as an :class:`InitialState` (unchecked)."""
    axis = states['axis'][i]
    return InitialState(
        states['position'][i],
        states['velocity'][i],
        axis,
        states['transverse_rate'][i],
        float(states['spin'][i]),
        frames.attitude_with_axis(axis),
    )
