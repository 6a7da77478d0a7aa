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
        raise ReleaseError(
            f"'{name}' = {_brief(value)} is outside the accepted range [{exact(lo)}, {exact(hi)}]"
        ) from None
    if not math.isfinite(value):
        raise ReleaseError(f"'{name}' must be finite, got {value}")
    pad = slack * (hi - lo)
    if not lo - pad <= value <= hi + pad:
        raise ReleaseError(
            f"'{name}' = {exact(value)} is outside the accepted range [{exact(lo)}, {exact(hi)}]"
        )
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


def exact(x: float) -> str:
    """Return ``x`` as the shortest text that reads back as the same float ('60', '60.00002')."""
    x = float(x)
    return str(int(x)) if x.is_integer() and abs(x) < 1e16 else repr(x)


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


def check_rigid_body(velocity, attitude, angular_velocity, height: float) -> float:
    """
    Check the combined limits of a rigid-body state in ``field``; return the norm of ``attitude``.

    ``velocity`` [m/s], ``attitude`` (x, y, z, w; body x = axis), ``angular_velocity`` [rad/s]:
    finite 3- and 4-sequences of floats, ``height`` the release point's z [m]. Raises
    ReleaseError for a speed, elevation, spin, axis offset or transverse rate outside LIMITS,
    an attitude that is not a unit quaternion, or a release on the ground heading down (the
    rules of :meth:`InitialState.from_rigid_body`, in plain floats).
    """
    vx, vy, vz = velocity
    check_range('speed', math.hypot(vx, vy, vz), slack=DERIVED_SLACK)  # hypot: no overflow
    check_range(
        'elevation_deg', math.degrees(math.atan2(vz, math.hypot(vx, vy))), slack=DERIVED_SLACK
    )
    norm = math.hypot(*attitude)
    if abs(norm - 1.0) > 1e-3:
        raise ReleaseError(f'orientation must be a unit quaternion, |q| = {exact(norm)}')
    x, y, z, w = (c / norm for c in attitude)
    axis = (1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y))  # body x
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    along = (axis[0] * vx + axis[1] * vy + axis[2] * vz) / speed
    delta = math.degrees(math.acos(min(1.0, max(-1.0, along))))
    check_range('axis offset from the velocity (deg)', delta, 'axis_offset_deg', DERIVED_SLACK)
    wx, wy, wz = angular_velocity
    spin = wx * axis[0] + wy * axis[1] + wz * axis[2]
    check_range('spin_rpm', spin / RPM, slack=DERIVED_SLACK)
    check_range(
        'transverse angular rate (deg/s)',
        math.degrees(math.hypot(wx - spin * axis[0], wy - spin * axis[1], wz - spin * axis[2])),
        'transverse_rate_deg_s',
        DERIVED_SLACK,
    )
    if height <= 0.0 and vz <= 0.0:
        raise ReleaseError('a release on the ground (z = 0) must go up (positive elevation)')
    return norm


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
        norm = check_rigid_body(vel.tolist(), quat.tolist(), omega.tolist(), float(pos[2]))
        quat = quat / norm
        axis = frames.body_x_axis(quat)
        spin = float(np.dot(omega, axis))
        transverse = omega - spin * axis
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
        # rules the simulator applies to every flight order, so that one truth decides. The
        # state is computed once, in plain floats, and kept for :meth:`initial_state`.
        position, velocity, axis, transverse, spin, attitude = _release_state(
            *(getattr(self, key) for key in STATE_KEYS), self.position
        )
        check_rigid_body(
            velocity, attitude, tuple(t + spin * a for t, a in zip(transverse, axis)), position[2]
        )
        object.__setattr__(self, '_state', (position, velocity, axis, transverse, spin, attitude))

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
        """
        Return the rigid-body state in ``field`` this release means (docs/physics.md sec. 1).

        The numbers of :func:`release_states` (bit for bit), computed once at validation; each
        call returns fresh arrays.
        """
        position, velocity, axis, transverse, spin, attitude = self._state
        return InitialState(
            np.array(position), np.array(velocity), np.array(axis), np.array(transverse), spin,
            np.array(attitude),
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


def _release_state(speed, elevation_deg, azimuth_deg, spin_rpm, alpha0_deg, beta0_deg,
                   alpha_rate_deg_s, beta_rate_deg_s, position):
    """
    :func:`release_states` and :func:`initial_state_of` for one release, in plain floats.

    The same operations in the same order (the vectorised path's sums run left to right), so
    the same numbers bit for bit; returns (position, velocity, axis, transverse_rate, spin,
    attitude) as tuples and a float. The attitude's last normalisation is numpy's own.
    """
    elev, azim = math.radians(elevation_deg), math.radians(azimuth_deg)
    alpha, beta = math.radians(alpha0_deg), math.radians(beta0_deg)
    ce = math.cos(elev)
    velocity = (speed * (ce * math.cos(azim)), speed * (ce * math.sin(azim)),
                speed * math.sin(elev))
    e1 = _unit3(velocity)
    e2 = _unit3((0.0 - e1[2] * e1[0], 0.0 - e1[2] * e1[1], 1.0 - e1[2] * e1[2]))
    e3 = _cross3(e1, e2)
    ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
    c0, c1, c2 = cb * ca, cb * sa, sb
    axis = tuple(c0 * e1[i] + c1 * e2[i] + c2 * e3[i] for i in range(3))
    rate_a, rate_b = math.radians(alpha_rate_deg_s), math.radians(beta_rate_deg_s)
    c0 = rate_a * (-cb * sa) + rate_b * (-sb * ca)
    c1 = rate_a * (cb * ca) + rate_b * (-sb * sa)
    c2 = rate_a * 0.0 + rate_b * cb
    axis_rate = tuple(c0 * e1[i] + c1 * e2[i] + c2 * e3[i] for i in range(3))
    position = tuple(float(p) for p in position)
    return (position, velocity, axis, _cross3(axis, axis_rate), spin_rpm * RPM,
            attitude_with_axis_scalar(axis))


def _unit3(v: tuple) -> tuple:
    norm = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / norm, v[1] / norm, v[2] / norm)


def _cross3(a: tuple, b: tuple) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def attitude_with_axis_scalar(axis) -> tuple[float, float, float, float]:
    """
    Return :func:`football_ros.physics.frames.attitude_with_axis` of one axis, in plain floats.

    ``axis`` a 3-sequence in ``field`` (normalised here); the quaternion (x, y, z, w) whose
    body x is the axis and body z as close to up as it can be, the same numbers bit for bit.
    """
    x = _unit3(axis)
    if abs(x[2]) < 0.999:
        z = _unit3((0.0 - x[2] * x[0], 0.0 - x[2] * x[1], 1.0 - x[2] * x[2]))
    else:
        z = _unit3((1.0 - x[0] * x[0], 0.0 - x[0] * x[1], 0.0 - x[0] * x[2]))
    y = _cross3(z, x)
    # quaternion_from_matrix of the columns (x, y, z): m[i][j] = column j, row i.
    m00, m11, m22 = x[0], y[1], z[2]
    trace = m00 + m11 + m22
    if trace > 0.0:
        k = 2.0 * math.sqrt(trace + 1.0)
        q = [(y[2] - z[1]) / k, (z[0] - x[2]) / k, (x[1] - y[0]) / k, 0.25 * k]
    elif m00 > m11 and m00 > m22:
        k = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = [0.25 * k, (y[0] + x[1]) / k, (z[0] + x[2]) / k, (y[2] - z[1]) / k]
    elif m11 > m22:
        k = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = [(y[0] + x[1]) / k, 0.25 * k, (z[1] + y[2]) / k, (z[0] - x[2]) / k]
    else:
        k = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = [(z[0] + x[2]) / k, (z[1] + y[2]) / k, 0.25 * k, (x[1] - y[0]) / k]
    q = np.array(q)
    return tuple((q / np.linalg.norm(q)).tolist())


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
