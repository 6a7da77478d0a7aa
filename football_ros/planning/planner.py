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
The throw planner: target point in ``field`` -> speed, elevation, azimuth and release attitude.

Aim. The ball's centre must pass through the target T. The planner shoots on the package's own
flight (the real-time kernel of :class:`football_ros.physics.Flight`, RK4 at the simulator's
step, compiled in :mod:`.kernels` and stopped at the target plane): the miss is measured where
the flown path crosses the vertical plane through T perpendicular to the horizontal line from
the release point to T (a lateral and a vertical offset, cubic Hermite inside the step), and
Newton steps with a finite-difference Jacobian and Broyden updates drive it below
``SOLVE_TOLERANCE``. Two equations, three unknowns: the objective fixes the third.
``fastest``: the flat arc at the largest speed; ``flat`` / ``lofted``: the two arcs at the given
speed; ``lowest_speed``: the elevation that needs the least speed (where the two arcs meet); a
wanted arrival time replaces the objective by a third equation.

Attitude. The least wobble is not the axis along the velocity: the spin momentum can follow the
turning velocity only with the nose at the equilibrium sideslip. The release puts the axis on
the local quasi-steady equilibrium X_p of the linear theory (docs/physics.md, linear theory:
x_p = -F/C of the flown model plus its first-order drift B x_p'/C, against the air) and lets it
turn with the velocity frame (w_V = -g cos(Phi)/U about e3) and the equilibrium's drift x_p':
the release whose mode amplitudes K1 = K2 = 0 (C1 = C2 = 0 for the paper's frozen theory).
``attitude='refined'`` then minimises the wobble of the whole nonlinear flight over the four
attitude numbers (the axis' deviation from X_p linearised in them by four more flights, its
largest value minimised: :func:`_refine`) and aims again. Where the equilibrium lies beyond
the linear theory (more than 30 deg off the air velocity: slow lobs, s3p ~ 1/V^3) the axis goes
along the air velocity, turning with it, and the plan warns (:meth:`_Shooter.axis_rate`).

Wobble amplitude (:func:`wobble_of`): the largest angle between the spin axis and the local
quasi-steady equilibrium axis X_p(t) (velocity frame of the local air velocity, the local speed,
path angle and spin), over the flight from release to the arrival at the target.

Check. A solved plan is flown once more from its :class:`Release`'s own initial state, as
:class:`Flight` flies it (the step rules of ``check_flyable``, the real-time kernel's RK4 steps
by :func:`kernels.fly`), with the ground at z = 0, to just past the target plane; its closest
approach to T must be within ``tolerance``; otherwise :class:`PlanError`. Every refusal names
the limit and, where one exists, the closest reachable point (the nearest of the points a scan
of elevations at the limiting speed reaches).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import math
from typing import Any, Sequence

import numpy as np

from . import kernels
from ..physics import dynamics as dyn
from ..physics import frames
from ..physics.aero import resolve
from ..physics.flight import DEFAULT_STEP, Flight
from ..physics.linear_theory import moment_slope, scalar_constants
from ..physics.modes import flight_warnings
from ..physics.release import (
    attitude_with_axis_scalar,
    initial_state_of,
    InitialState,
    LIMITS,
    Release,
    release_states,
    ReleaseError,
    RPM,
)
from ..physics.step_stability import check_flyable

OBJECTIVES = ('fastest', 'lowest_speed', 'flat', 'lofted')
ATTITUDES = ('equilibrium', 'linear', 'refined', 'aligned')
DEFAULT_MAX_SPEED = 35.0
"""Largest release speed [m/s] a plan may use unless told (a strong quarterback's is ~30)."""
DEFAULT_ELEVATION_RANGE = (-45.0, 80.0)
"""Accepted release elevations [deg] unless told."""
SOLVE_TOLERANCE = 1e-3
"""Miss [m] at which the shooting stops."""
CHECK_TOLERANCE = 0.01
"""Largest accepted miss [m] of the checking flight."""
MAX_FLIGHTS = 60
"""Flights one aim may fly before it gives up."""
MIN_HORIZONTAL = 0.5
"""Smallest horizontal distance [m] from the release point to the target."""


class PlanError(ValueError):
    """
    A target no release reaches within the limits; the message names the limit.

    ``limit``: the limit's name, ``closest``: the closest reachable point in ``field`` [m] (or
    None where the question has no answer, e.g. a non-finite target).
    """

    def __init__(self, message: str, limit: str = '', closest: np.ndarray | None = None):
        if closest is not None:
            c = np.asarray(closest, dtype=float)
            message += f'; closest reachable point ({c[0]:.2f}, {c[1]:.2f}, {c[2]:.2f}) m'
        super().__init__(message)
        self.limit = limit
        self.closest = None if closest is None else np.asarray(closest, dtype=float)


@dataclass(frozen=True)
class Receiver:
    """
    A receiver moving at constant ``velocity`` [m/s], at ``position`` [m] at ``time`` [s].

    ``time`` is counted from the release (0: where it is at the release); ``field`` frame.
    """

    position: Sequence[float]
    velocity: Sequence[float]
    time: float = 0.0

    def at(self, t: float) -> np.ndarray:
        """Position [m] at ``t`` [s] after the release."""
        return np.asarray(self.position, float) + np.asarray(self.velocity, float) * (
            t - self.time
        )


@dataclass(frozen=True)
class Plan:
    """
    A checked plan. ``release`` flies it (:meth:`Flight.from_release`, the given step).

    target and arrival_point [m] in ``field``, arrival_time [s] after release (closest
    approach), miss_m [m], arrival_delta_deg: angle between axis and air velocity at arrival,
    wobble_deg (:func:`wobble_of`) and the same two for the aligned release (axis along the
    velocity, not rotating, same speed and direction; flown in steps of :data:`ALIGNED_STEP`),
    linear_release: the analytic (C1 = C2 = 0) attitude, path_times [s] / path_positions
    (N, 3) [m] of the checking flight to the arrival (its samples, then the arrival point
    itself).
    """

    release: Release
    objective: str
    arc: str
    target: np.ndarray
    arrival_time: float
    arrival_point: np.ndarray
    miss_m: float
    arrival_delta_deg: float
    wobble_deg: float
    aligned_wobble_deg: float
    aligned_arrival_delta_deg: float
    attitude: str
    linear_release: dict[str, float]
    flights: int
    path_times: np.ndarray = field(repr=False)
    path_positions: np.ndarray = field(repr=False)
    warnings: tuple[str, ...] = ()

    @property
    def sentence(self) -> str:
        """Describe the release attitude in words."""
        r = self.release
        if self.attitude == 'aligned':
            return 'axis along the velocity, not rotating'
        side = 'right' if r.beta0_deg >= 0 else 'left'
        up = 'above' if r.alpha0_deg >= 0 else 'below'
        text = (
            f'nose {abs(r.beta0_deg):.1f} deg {side} of the velocity and '
            f'{abs(r.alpha0_deg):.1f} deg {up} it, turning with it '
            f'({r.alpha_rate_deg_s:+.1f} deg/s pitch, {r.beta_rate_deg_s:+.1f} deg/s yaw)'
        )
        if any(r.aero.get('wind') or ()):
            text += ' (angles against the ground velocity; the equilibrium is against the air)'
        return text

    def to_mapping(self) -> dict[str, Any]:
        """JSON-safe form: the release options' names, then the plan's numbers."""
        r = self.release
        out: dict[str, Any] = {
            'ball': r.ball,
            'speed': r.speed,
            'elevation_deg': r.elevation_deg,
            'azimuth_deg': r.azimuth_deg,
            'spin_rpm': r.spin_rpm,
            'alpha0_deg': r.alpha0_deg,
            'beta0_deg': r.beta0_deg,
            'alpha_rate_deg_s': r.alpha_rate_deg_s,
            'beta_rate_deg_s': r.beta_rate_deg_s,
            'position': list(r.position),
            'model': r.model,
            'moment': r.moment,
            'ball_params': dict(r.ball_params),
            'aero': dict(r.aero),
            'target': [float(v) for v in self.target],
            'objective': self.objective,
            'arc': self.arc,
            'arrival_time': self.arrival_time,
            'arrival_point': [float(v) for v in self.arrival_point],
            'miss_m': self.miss_m,
            'arrival_delta_deg': self.arrival_delta_deg,
            'wobble_deg': self.wobble_deg,
            'aligned_wobble_deg': self.aligned_wobble_deg,
            'aligned_arrival_delta_deg': self.aligned_arrival_delta_deg,
            'attitude': self.attitude,
            'attitude_sentence': self.sentence,
            'linear_release': dict(self.linear_release),
            'flights': self.flights,
            'warnings': list(self.warnings),
        }
        return out

    def release_mapping(self) -> dict[str, Any]:
        """Return the plan as a release request's keys (:meth:`Release.to_mapping`)."""
        return self.release.to_mapping()


# --- the least-wobble attitude -------------------------------------------------------
def _vec(v) -> tuple[float, float, float]:
    """Plain-float 3-tuple of a vector."""
    return float(v[0]), float(v[1]), float(v[2])


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b) -> tuple[float, float, float]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def equilibrium_attitude(
    params: np.ndarray, velocity: Sequence[float], h1: float, drift: bool = True
) -> dict[str, float]:
    """
    Return the least-wobble release attitude as release options (degrees, deg/s).

    The axis and rate of :func:`kernels.release_axis` (``params``: kernel parameters, wind
    included; ``velocity`` [m/s] in ``field``; ``h1`` = (I_s/I_t) p [rad/s]) as the release
    options: angles against the ground velocity, rates relative to ``field``
    (:func:`football_ros.physics.release.release_states`).
    """
    velocity = _vec(velocity)
    wind = tuple(float(w) for w in params[dyn.P_WIND:dyn.P_WIND + 3])
    axis, rate = kernels.release_axis(scalar_constants(params), wind, velocity, float(h1), drift)
    return _options(velocity, axis, rate)


def _options(velocity, axis, rate) -> dict[str, float]:
    """
    Return the release options (deg, deg/s) of an axis and its rate in ``field``.

    Angles against ``velocity`` (its frame, :func:`football_ros.physics.frames.velocity_frame`);
    3-sequences of floats.
    """
    alpha, beta, alpha_rate, beta_rate = kernels.release_options(_vec(velocity), _vec(axis),
                                                                 _vec(rate))
    return {
        'alpha0_deg': alpha,
        'beta0_deg': beta,
        'alpha_rate_deg_s': alpha_rate,
        'beta_rate_deg_s': beta_rate,
    }


WOBBLE_SAMPLE = 0.005
"""Spacing [s] of the samples the wobble amplitude is taken over (the nutation period of a
pass is about 0.2 s: the largest angle between samples is then within 0.1 % of the true one)."""


ALIGNED_STEP = WOBBLE_SAMPLE / 2
"""Step [s] of the aligned release's comparison flight (the simulator's step if that is
larger, or if this one breaks the step rules): RK4 at 2.5 ms puts its wobble and delta within
1e-3 deg, the plan's printed digits, of the simulator's 1 ms steps (test_planner checks it on
random plans, spins up to 900 rpm)."""


def aligned_step(step: float, largest_step: float) -> float:
    """
    Return the step [s] the aligned release's comparison flight takes (:data:`ALIGNED_STEP`).

    ``step`` [s] the simulator's, ``largest_step`` [s] the largest the step rules allow the
    planned release (:func:`football_ros.physics.step_stability.check_flyable`; the aligned one
    turns no faster).
    """
    return ALIGNED_STEP if step < ALIGNED_STEP <= largest_step else step


def wobble_of(
    times: np.ndarray, states: np.ndarray, params: np.ndarray, until: float | None = None
) -> tuple[float, float]:
    """
    Return (wobble amplitude, angle between axis and air velocity at the end) [deg].

    The wobble amplitude: the largest angle between the spin axis and the local quasi-steady
    equilibrium axis X_p (module docstring) over the samples with t <= ``until`` [s], taken
    every ``WOBBLE_SAMPLE`` (and the last one); the second number is delta at the last of them.
    ``states`` (N, N_STATE) of the real-time kernel.
    """
    return _wobbles(((times, states),), params, until)[0]


def _wobbles(parts, params: np.ndarray, until: float | None = None) -> list[tuple[float, float]]:
    """Return :func:`wobble_of` of several sampled flights (times, states): compiled passes."""
    consts = scalar_constants(params)
    return [tuple(math.degrees(v) for v in kernels.wobble(
        np.ascontiguousarray(states), _wobble_rows(times, until), params, consts))
        for times, states in parts]


def _wobble_rows(times: np.ndarray, until: float | None = None) -> np.ndarray:
    """Return the rows the wobble amplitude is taken over (:func:`wobble_of`)."""
    n = int(np.searchsorted(times, (times[-1] if until is None else until) + 1e-12, 'right'))
    if n <= 2:  # times increase: the samples with t <= until are the first n
        return np.arange(n)
    stride = _wobble_stride(times[1] - times[0])
    every = np.arange(0, n, stride)
    return every if every[-1] == n - 1 else np.append(every, n - 1)


def _wobble_stride(step: float) -> int:
    """Return the rows between wobble samples of a flight sampled every ``step`` [s]."""
    return max(1, int(round(WOBBLE_SAMPLE / max(step, 1e-9))))


def _wobble_samples(times: np.ndarray, states: np.ndarray, until: float | None = None):
    """Return the states the wobble amplitude is taken over (:func:`wobble_of`)."""
    return states[_wobble_rows(times, until)]


def _axis_and_equilibrium(states: np.ndarray, params: np.ndarray):
    """Return the spin axis and the equilibrium axis X_p (unit, (N, 3), ``field``)."""
    return kernels.equilibrium_axes(np.ascontiguousarray(states), params,
                                    scalar_constants(params))


def _angle_deg(a, b) -> float:
    """Angle [deg] between two unit vectors (3-sequences)."""
    return math.degrees(math.acos(min(1.0, max(-1.0, _dot(a, b)))))


MAX_EQUILIBRIUM_DEG = 30.0
"""Largest equilibrium offset from the air velocity [deg] the release trusts (the linear
theory's small-angle range; slow lofted throws put it far beyond)."""
MAX_OFFSET_DEG = 55.0
"""Largest release offset of the axis from the velocity [deg] (the release limit is 60)."""
MAX_RATE_DEG_S = 3000.0
"""Largest release axis rate [deg/s] (the release limit is 3600)."""


# --- flying ----------------------------------------------------------------
class _Shooter:
    """One base release (ball, spin, point, model) flown toward one target plane."""

    def __init__(self, base: Release, step: float) -> None:
        self.base, self.step = base, step
        self.ball, self.aero = resolve(base.preset(), base.model, base.aero_model())
        self.params = dyn.make_params(self.ball, base.moment, self.aero)
        self.gravity = float(self.params[dyn.P_GRAVITY])
        self.consts = scalar_constants(self.params)
        self.wind = _vec(self.params[dyn.P_WIND:dyn.P_WIND + 3])
        self.h1 = self.ball.inertia_ratio * base.spin_rpm * RPM
        self.r0 = np.array(base.position, dtype=float)
        self.flights = 0
        self.offsets = np.zeros(4)  # refined attitude - equilibrium (deg, deg, deg/s, deg/s)
        self.mode = 'equilibrium'
        self._last_cross = None
        self.aim(np.array([self.r0[0] + 10.0, self.r0[1], self.r0[2]]))

    def aim(self, target: np.ndarray) -> None:
        """Set the target T and the plane's axes (downrange d, left n)."""
        self.target = np.asarray(target, dtype=float)
        (tx, ty, tz), (rx, ry, rz) = self.target.tolist(), self.r0.tolist()
        fx, fy = tx - rx, ty - ry
        self.distance = float(np.hypot(fx, fy))
        self.bearing = math.atan2(fy, fx)
        c, s = math.cos(self.bearing), math.sin(self.bearing)
        self.d = np.array([c, s, 0.0])
        self.n = np.array([-s, c, 0.0])
        self.height = tz - rz
        self.last_time = None

    def axis_rate(self, speed: float, elev: float, azim: float):
        """
        Return (velocity, axis, axis rate, note) of a release in the current mode (``field``).

        The equilibrium when the linear theory holds there (axis within ``MAX_EQUILIBRIUM_DEG``
        of the air velocity, within ``MAX_OFFSET_DEG`` of the velocity, rate below
        ``MAX_RATE_DEG_S``); else the axis along the air velocity turning with it; else along
        the velocity, not rotating. ``note`` says which fallback was taken ('' for none).
        Vectors as 3-tuples of floats.
        """
        vel = _direction(speed, elev, azim)
        ground = (vel[0] / speed, vel[1] / speed, vel[2] / speed)
        if self.mode == 'aligned':
            return vel, ground, (0.0, 0.0, 0.0), ''
        axis, rate = kernels.release_axis(self.consts, self.wind, vel, self.h1,
                                          self.mode != 'linear')
        wind = self.wind
        air = (vel[0] - wind[0], vel[1] - wind[1], vel[2] - wind[2])
        air_speed = math.sqrt(_dot(air, air))
        e1 = (air[0] / air_speed, air[1] / air_speed, air[2] / air_speed)
        off_air = _angle_deg(axis, e1)
        if (off_air <= MAX_EQUILIBRIUM_DEG and _angle_deg(axis, ground) <= MAX_OFFSET_DEG
                and math.degrees(math.sqrt(_dot(rate, rate))) <= MAX_RATE_DEG_S):
            return vel, axis, rate, ''
        note = (f'the equilibrium is {off_air:.0f} deg off the air velocity (beyond the linear '
                'theory): axis along the air velocity, turning with it')
        if _angle_deg(e1, ground) <= MAX_OFFSET_DEG:
            omega_v = -self.gravity * math.hypot(e1[0], e1[1]) / air_speed
            e2 = frames.velocity_frame(np.array(air))[1]
            return vel, e1, _vec(omega_v * e2), note
        return vel, ground, (0.0, 0.0, 0.0), (
            f'the air velocity is {_angle_deg(e1, ground):.0f} deg off the velocity (wind): '
            'axis along the velocity, not rotating')

    def attitude(self, speed: float, elev: float, azim: float) -> dict[str, float]:
        """Release attitude options for a release (degrees) in the current mode."""
        return self.attitude_note(speed, elev, azim)[0]

    def attitude_note(self, speed: float, elev: float, azim: float):
        """Return (:meth:`attitude`, the note of :meth:`axis_rate`)."""
        vel, axis, rate, note = self.axis_rate(speed, elev, azim)
        att = _options(vel, axis, rate)
        if any(self.offsets.tolist()):
            for key, off in zip(att, self.offsets):
                att[key] += float(off)
        return att, note

    def y0(self, speed: float, elev: float, azim: float, h1: float | None = None) -> np.ndarray:
        """
        State vector of the real-time kernel, built as :class:`Flight` builds it.

        ``h1`` [rad/s]: the modified spin (default: the base release's), without offsets only.
        """
        if not any(self.offsets.tolist()):
            # The release's axis and rate directly (what the release options give, to
            # round-off, without the detour through angles).
            vel, axis, rate, _ = self.axis_rate(speed, elev, azim)
            if h1 is None:
                h1 = self.ball.inertia_ratio * self.base.spin_rpm * RPM
            turn = _cross(axis, rate)
            y0 = np.zeros(dyn.N_STATE)
            y0[dyn.R:dyn.R + 3] = self.r0
            y0[dyn.V:dyn.V + 3] = vel
            y0[dyn.Q:dyn.Q + 4] = attitude_with_axis_scalar(axis)
            y0[dyn.H:dyn.H + 3] = [turn[i] + h1 * axis[i] for i in range(3)]
            y0[dyn.H1] = h1
            return y0
        att = self.attitude(speed, elev, azim)
        st = initial_state_of(
            release_states(
                speed,
                elev,
                azim,
                self.base.spin_rpm,
                att['alpha0_deg'],
                att['beta0_deg'],
                att['alpha_rate_deg_s'],
                att['beta_rate_deg_s'],
                self.r0,
            )
        )
        y0 = np.zeros(dyn.N_STATE)
        y0[dyn.R:dyn.R + 3] = st.position
        y0[dyn.V:dyn.V + 3] = st.velocity
        y0[dyn.Q:dyn.Q + 4] = st.attitude
        y0[dyn.H:dyn.H + 3] = st.modified_momentum(self.ball)
        y0[dyn.H1] = self.ball.inertia_ratio * st.spin
        return y0

    def cross_vacuum(self, speed: float, elev: float, azim: float):
        """Return :meth:`cross` of the vacuum parabola (closed form; None if never there)."""
        vel = _direction(speed, elev, azim)
        d, n, r0, target = self.d, self.n, self.r0, self.target
        along = vel[0] * d[0] + vel[1] * d[1]
        if along <= 0.0:
            return None
        t = ((target[0] - r0[0]) * d[0] + (target[1] - r0[1]) * d[1]) / along
        off_x = r0[0] + vel[0] * t - target[0]
        off_y = r0[1] + vel[1] * t - target[1]
        off_z = r0[2] + vel[2] * t - 0.5 * self.gravity * t * t - target[2]
        return off_x * n[0] + off_y * n[1], off_z, t

    def duration_guess(self, speed: float, elev: float) -> float:
        horizontal = max(speed * math.cos(math.radians(elev)), 1.0)
        return min(1.6 * self.distance / horizontal + 0.3, 30.0)

    def cross(self, speed: float, elev: float, azim: float, ground: float = -1e4):
        """
        Fly and return (lateral, vertical, time) where the path crosses the target plane.

        lateral [m] > 0 left of T, vertical [m] > 0 above it, time [s]; None if it never
        does within 30 s (or lands first when ``ground`` is the real one). The paper's
        centre flies the vacuum parabola whatever the attitude (v' = -g; RK4 integrates it
        exactly): its crossing is computed in closed form, and the checking flight flies it.
        """
        if self.base.model == 'paper':
            return self.cross_vacuum(speed, elev, azim)
        key = (float(speed), float(elev), float(azim), float(ground), self.mode,
               tuple(self.offsets), tuple(self.target))
        if self._last_cross is not None and self._last_cross[0] == key:
            return self._last_cross[1]  # the same flight again (a guard, then Newton's start)
        out = self._fly_to_plane(speed, elev, azim, ground)
        self._last_cross = (key, out)
        return out

    def _fly_to_plane(self, speed: float, elev: float, azim: float, ground: float):
        y0 = self.y0(speed, elev, azim)
        if self.last_time is not None:  # the last crossing, with a margin
            duration = min(1.1 * self.last_time + 0.05, 30.0)
        else:
            duration = self.duration_guess(speed, elev)
        while True:
            self.flights += 1
            times, states, landed = kernels.fly(
                y0, self.step, self.params, duration, ground, self.target, self.d, 0
            )
            found, t, p = kernels.plane_crossing(times, states, self.target, self.d)
            if found:
                off = p - self.target
                self.last_time = float(t)
                return float(off @ self.n), float(off[2]), t
            if landed or duration >= 30.0:
                return None
            duration = min(2.0 * duration, 30.0)


def _direction(speed: float, elev: float, azim: float) -> tuple[float, float, float]:
    """
    Return the velocity [m/s] in ``field`` of a speed, elevation and azimuth [deg].

    :func:`football_ros.physics.frames.direction` in plain floats.
    """
    e, a = math.radians(elev), math.radians(azim)
    ce = math.cos(e)
    return speed * (ce * math.cos(a)), speed * (ce * math.sin(a)), speed * math.sin(e)


def closest_approach(times, states, target) -> tuple[float, float, np.ndarray]:
    """
    Closest approach of a sampled path to ``target``: (distance [m], time [s], point [m]).

    On the cubic Hermite interpolant of the samples' positions and velocities (201 points in
    each of the two steps beside the closest sample; :func:`kernels.closest_approach`).
    """
    dist, t, point = kernels.closest_approach(
        np.ascontiguousarray(times, dtype=float), np.ascontiguousarray(states, dtype=float),
        np.asarray(target, dtype=float), kernels.APPROACH_POINTS)
    return float(dist), float(t), point


# --- solving ----------------------------------------------------------------
def _largest(r: np.ndarray) -> float:
    """Return ``float(np.max(np.abs(r)))`` of a short residual in plain floats (NaN wins)."""
    out = 0.0
    for v in r.tolist():
        v = abs(v)
        if v != v:
            return math.nan
        if v > out:
            out = v
    return out


def _newton(fun, x0: np.ndarray, steps: np.ndarray, lo, hi, budget: int, model=None):
    """
    Solve fun(x) = 0 (fun: array or None) from ``x0`` inside [lo, hi].

    Finite-difference Jacobian (forward ``steps``), Broyden updates, step halving. ``model``:
    a cheap approximation of ``fun`` (the vacuum parabola) whose Jacobian starts the
    iteration; the flown one replaces it when progress is slow. Returns (x, residual) of the
    best point, or (None, None) if no point could be flown.
    """
    x = np.minimum(np.maximum(np.asarray(x0, dtype=float), lo), hi)  # np.clip, cheaper
    r = fun(x)
    if r is None:
        return None, None
    jac = None
    evals = 1
    use_model = model is not None
    while evals < budget and _largest(r) > SOLVE_TOLERANCE:
        fresh = jac is None and not use_model
        if jac is None:
            f, r_ref = (model, model(x)) if use_model else (fun, r)
            use_model = False
            jac = np.empty((len(r), len(x)))
            for i, h in enumerate(steps):
                xi = x.copy()
                xi[i] += h if xi[i] + h <= hi[i] else -h
                ri = f(xi)
                if f is fun:
                    evals += 1
                if ri is None or r_ref is None:
                    return x, r
                jac[:, i] = (ri - r_ref) / (xi[i] - x[i])
        try:
            dx = -np.linalg.solve(jac, r)
        except np.linalg.LinAlgError:
            dx = -np.linalg.lstsq(jac, r, rcond=None)[0]
        scale = 1.0
        improved = False
        for _ in range(6):
            xn = np.minimum(np.maximum(x + scale * dx, lo), hi)
            rn = fun(xn)
            evals += 1
            if rn is not None and np.linalg.norm(rn) < np.linalg.norm(r):
                improved = True
                break
            scale *= 0.5
        if not improved:
            if fresh:
                return x, r
            jac = None
            continue
        step = xn - x
        if step @ step > 0.0:
            jac = jac + np.outer(rn - r - jac @ step, step) / (step @ step)
        ratio = np.linalg.norm(rn) / max(np.linalg.norm(r), 1e-300)
        x, r = xn, rn
        if ratio > 0.5:
            jac = None  # slow progress: a fresh Jacobian
    return x, r


def _vacuum_elevation(speed: float, distance: float, height: float, g: float, lofted: bool):
    """Vacuum elevation [deg] reaching (distance, height) at ``speed``, or None if out of reach."""
    v2 = speed * speed
    disc = v2 * v2 - g * (g * distance * distance + 2.0 * height * v2)
    if disc < 0.0:
        return None
    root = math.sqrt(disc)
    return math.degrees(math.atan2(v2 + root if lofted else v2 - root, g * distance))


def _vacuum_speed(elev: float, distance: float, height: float, g: float):
    """Vacuum speed [m/s] at elevation ``elev`` [deg] for (distance, height), or None."""
    c, t = math.cos(math.radians(elev)), math.tan(math.radians(elev))
    denom = 2.0 * c * c * (distance * t - height)
    return math.sqrt(g * distance * distance / denom) if denom > 0.0 else None


def _vacuum_time(speed: float, distance: float, height: float, g: float) -> float | None:
    """Flight time [s] of the flat vacuum arc at ``speed`` (None: out of its reach)."""
    elev = _vacuum_elevation(speed, distance, height, g, False)
    return None if elev is None else distance / (speed * math.cos(math.radians(elev)))


def _lowest_speed_elevation(distance: float, height: float) -> float:
    """Vacuum elevation [deg] of the least speed: 45 deg + half the angle to the target."""
    return 45.0 + 0.5 * math.degrees(math.atan2(height, distance))


def _plain(values) -> str:
    """Numbers as the user wrote them: '[1, nan, 2.5]' (no numpy reprs)."""
    return '[' + ', '.join(f'{float(v):g}' for v in values) + ']'


def _check_target(target, name: str = 'target') -> np.ndarray:
    """Return a finite point on or above the ground inside the field limits, else raise."""
    try:
        arr = np.asarray(target, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise PlanError(f"'{name}' must be 3 numbers [x, y, z] in field (m)", name) from None
    if arr.size != 3:
        raise PlanError(f"'{name}' must be 3 numbers [x, y, z] in field (m)", name)
    x, y, z = arr.tolist()  # plain floats: cheaper to compare than numpy scalars
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
        raise PlanError(f"'{name}' must be finite, got {_plain(arr)}", name)
    if z < 0.0:
        raise PlanError(
            f"'{name}' is below the ground (z = {z:g} m < 0)",
            'ground',
            np.array([x, y, 0.0]),
        )
    lo, hi = LIMITS['position_xy']
    if not (lo <= x <= hi and lo <= y <= hi and z <= LIMITS['position_z'][1]):
        raise PlanError(f"'{name}' = {_plain(arr)} is outside the field limits", name)
    return arr


class _Aim:
    """The aim problems of one request."""

    def __init__(self, shooter: _Shooter, max_speed: float, elev_range: tuple[float, float]):
        self.sh, self.max_speed, self.elev_range = shooter, max_speed, elev_range
        self.speed_lo = LIMITS['speed'][0]
        self.elev_lo, self.elev_hi = LIMITS['elevation_deg']

    def _fixed_speed(self, speed: float, elev0: float, azim0: float):
        sh = self.sh
        if sh.cross(speed, elev0, azim0) is None:
            # Never at the target plane from this guess (a lofted arc blown back, a flat one
            # that falls short): walk toward the least-speed elevation until it gets there.
            centre = _lowest_speed_elevation(sh.distance, sh.height)
            for elev in np.linspace(elev0, centre, 9)[1:]:
                if sh.cross(speed, float(elev), azim0) is not None:
                    elev0 = float(elev)
                    break

        def fun(x):
            out = sh.cross(speed, x[0], x[1])
            return None if out is None else np.array(out[:2])

        def model(x):
            out = sh.cross_vacuum(speed, x[0], x[1])
            return None if out is None else np.array(out[:2])

        x, r = _newton(
            fun,
            np.array([elev0, azim0]),
            np.array([1e-3, 1e-3]),
            np.array([self.elev_lo, -720.0]),
            np.array([self.elev_hi, 720.0]),
            MAX_FLIGHTS,
            model,
        )
        return None if x is None else (speed, float(x[0]), float(x[1]), r)

    def _fixed_elevation(self, elev: float, speed0: float, azim0: float):
        sh = self.sh

        def fun(x):
            out = sh.cross(x[0], elev, x[1])
            return None if out is None else np.array(out[:2])

        def model(x):
            out = sh.cross_vacuum(x[0], elev, x[1])
            return None if out is None else np.array(out[:2])

        x, r = _newton(
            fun,
            np.array([speed0, azim0]),
            np.array([1e-3, 1e-3]),
            np.array([self.speed_lo, -720.0]),
            np.array([LIMITS['speed'][1], 720.0]),
            MAX_FLIGHTS,
            model,
        )
        return None if x is None else (float(x[0]), elev, float(x[1]), r)

    def at_time(self, arrival: float, guess=None):
        """Release reaching the target at ``arrival`` [s] (3 equations in speed, elev, azim)."""
        sh = self.sh
        if guess is None:
            delta = sh.target - sh.r0
            v = delta / arrival + np.array([0.0, 0.0, 0.5 * sh.gravity * arrival])
            speed = float(np.linalg.norm(v))
            guess = (
                min(max(speed, 1.0), 60.0),
                math.degrees(math.atan2(v[2], math.hypot(v[0], v[1]))),
                math.degrees(sh.bearing),
            )
        vref = max(sh.distance / arrival, 1.0)

        def fun(x, cross=sh.cross):
            out = cross(x[0], x[1], x[2])
            return None if out is None else np.array([out[0], out[1], (out[2] - arrival) * vref])

        x, r = _newton(
            fun,
            np.array(guess[:3], dtype=float),
            np.array([1e-3, 1e-3, 1e-3]),
            np.array([self.speed_lo, self.elev_lo, -720.0]),
            np.array([LIMITS['speed'][1], self.elev_hi, 720.0]),
            MAX_FLIGHTS,
            lambda x: fun(x, sh.cross_vacuum),
        )
        return None if x is None else (float(x[0]), float(x[1]), float(x[2]), r)

    def at_speed(self, speed: float, lofted: bool, guess=None):
        """Flat or lofted release at ``speed`` [m/s]."""
        sh = self.sh
        if guess is None:
            elev = _vacuum_elevation(speed, sh.distance, sh.height, sh.gravity, lofted)
            if elev is None:
                elev = _lowest_speed_elevation(sh.distance, sh.height) + (5.0 if lofted else -5.0)
            elif not lofted and sh.base.model != 'paper':
                elev += 2.0  # drag: a little higher than in vacuum (the paper's centre flies
                # the vacuum parabola: there the vacuum elevation is the answer)
            guess = (speed, elev, math.degrees(sh.bearing))
        return self._fixed_speed(speed, guess[1], guess[2])

    def lowest_speed(self):
        """Least-speed release: minimise the speed of the fixed-elevation aim over elevation."""
        sh = self.sh
        center = _lowest_speed_elevation(sh.distance, sh.height) - 3.0
        best = None
        memo: dict[float, tuple] = {}

        def speed_at(elev: float):
            nonlocal best
            elev = float(min(max(elev, self.elev_range[0]), self.elev_range[1]))
            if elev in memo:
                return memo[elev]
            speed0 = _vacuum_speed(elev, sh.distance, sh.height, sh.gravity)
            if best is not None:
                speed0 = best[0]
            if speed0 is None:
                speed0 = 20.0
            sol = self._fixed_elevation(elev, min(speed0, 60.0), best[2] if best else
                                        math.degrees(sh.bearing))
            if sol is not None and _largest(sol[3]) <= SOLVE_TOLERANCE:
                memo[elev] = sol
                if best is None or sol[0] < best[0]:
                    best = sol
            else:
                memo[elev] = None
            return memo[elev]

        width = 6.0
        for _ in range(4):  # successive parabolas on speed(elevation)
            pts = [(e, speed_at(e)) for e in (center - width, center, center + width)]
            good = [(e, s[0]) for e, s in pts if s is not None]
            if len(good) < 3:
                center, width = (best[1] if best else center), width / 2.0
                continue
            (e0, s0), (e1, s1), (e2, s2) = good
            denom = (e0 - e1) * (e0 - e2) * (e1 - e2)
            a = (e2 * (s1 - s0) + e1 * (s0 - s2) + e0 * (s2 - s1)) / denom
            bq = (e2 * e2 * (s0 - s1) + e1 * e1 * (s2 - s0) + e0 * e0 * (s1 - s2)) / denom
            vertex = -bq / (2.0 * a) if a > 0.0 else best[1]
            center = float(min(max(vertex, e0 - width), e2 + width))
            width = max(width / 3.0, 0.05)
        if best is not None:
            speed_at(center)
        return best


def _closest_reachable(sh: _Shooter, speed: float, elev_range) -> np.ndarray:
    """
    Return the point nearest to the target of the paths flown at ``speed`` toward it.

    A scan of 15 elevations in ``elev_range`` (from 0 deg up, if it reaches 0), the best refined
    between its neighbours (bounded scalar search, to 0.01 deg).
    """
    from scipy.optimize import minimize_scalar

    def reach(elev: float):
        y0 = sh.y0(speed, float(elev), math.degrees(sh.bearing))
        times, states, _ = kernels.fly(y0, sh.step, sh.params, 30.0, 0.0, sh.target, sh.d, -1)
        sh.flights += 1
        dist, _, point = closest_approach(times, states, sh.target)
        return dist, point

    grid = np.linspace(min(max(elev_range[0], 0.0), elev_range[1]), elev_range[1], 15)
    dists = [reach(e)[0] for e in grid]
    k = int(np.argmin(dists))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    best = minimize_scalar(lambda e: reach(e)[0], bounds=(lo, hi), method='bounded',
                           options={'xatol': 0.01})
    elev = best.x if best.fun < dists[k] else grid[k]
    return reach(elev)[1]


def plan(
    target: Sequence[float] | None = None,
    base: Release | None = None,
    objective: str = 'fastest',
    max_speed: float = DEFAULT_MAX_SPEED,
    elevation_range: tuple[float, float] = DEFAULT_ELEVATION_RANGE,
    receiver: Receiver | None = None,
    arrival_time: float | None = None,
    arrival_window: tuple[float, float] | None = None,
    attitude: str = 'equilibrium',
    step: float = DEFAULT_STEP,
    tolerance: float = CHECK_TOLERANCE,
    wobble: bool = True,
) -> Plan:
    """
    Plan the release that takes the ball's centre through ``target`` [m] in ``field``.

    ``base``: ball, spin (sign = hand), release point, model, aero and wind; its speed is the
    speed of the ``flat`` / ``lofted`` objectives. ``max_speed`` [m/s] and ``elevation_range``
    [deg] bound the release. ``receiver`` (instead of ``target``): a moving receiver the plan
    leads; ``arrival_time`` [s] fixes when the ball arrives, ``arrival_window`` (t_min, t_max)
    [s] bounds it. ``attitude``: 'equilibrium' (least wobble, quasi-steady linear theory with
    the equilibrium's drift), 'linear' (the frozen theory's C1 = C2 = 0), 'refined' (the
    equilibrium optimised over the nonlinear flight) or 'aligned' (axis along the velocity, not
    rotating).
    ``wobble=False`` skips the wobble numbers (NaN) and the aligned release's flight.
    Raises :class:`PlanError` for every target it cannot reach within the limits.
    """
    base = base or Release()
    args = [target, base, objective, max_speed, elevation_range, receiver, arrival_time,
            arrival_window, attitude, step, tolerance, wobble]
    if base.spin_rpm == 0.0:
        raise PlanError('spin_rpm is 0: a ball without spin has no gyroscopic stiffness and '
                        'tumbles; give the spin (its sign is the hand)', 'spin_rpm')
    if objective == 'fastest' and arrival_time is None and arrival_window is None:
        best = _fastest_stable(args)
    else:
        best = _plan(*args)
    if attitude != 'aligned' and wobble and best.aligned_wobble_deg < best.wobble_deg:
        args[1], args[8] = best.release, 'aligned'  # the aligned release of the same speed
        if objective == 'fastest' and arrival_time is None and arrival_window is None:
            args[2] = 'flat'  # at the speed planned (the fastest stable one), not max_speed
        aligned = replace(_plan(*args), objective=best.objective)
        if aligned.wobble_deg <= best.wobble_deg:
            return replace(aligned, warnings=aligned.warnings + (
                f'the aligned release wobbles less ({aligned.wobble_deg:.1f} deg) than the '
                f'{attitude} one ({best.wobble_deg:.1f} deg): the aligned release is '
                'planned',))
    return best


def _fastest_stable(args: list) -> Plan:
    """
    Plan the fastest release (``args`` of :func:`_plan`) that is gyroscopically stable.

    At max_speed when that release is stable; else at the speed whose air speed at release
    makes S_g = 1 (h1^2 = 4 M_alpha(V), less 0.1 %), found in a few passes (the direction
    and so the air speed change a little with the speed). Raises PlanError (limit
    'gyroscopic_stability') naming that speed when no stable release reaches the target.
    """
    base, max_speed = args[1], args[3]
    best = _plan(*args)
    for _ in range(4):
        sh = _Shooter(best.release, DEFAULT_STEP)
        initial = best.release.initial_state()
        if _gyroscopically_stable(sh, initial):
            return best
        air = math.dist(initial.velocity, sh.wind)
        critical = abs(sh.ball.inertia_ratio * initial.spin) / (
            2.0 * math.sqrt(moment_slope(sh.ball, 1.0)))
        speed = min(best.release.speed * critical / air * 0.999, max_speed)
        capped = list(args)
        capped[1], capped[2] = base.replace(speed=speed), 'flat'
        try:
            best = replace(_plan(*capped), objective='fastest')
        except PlanError as exc:
            raise PlanError(
                f'the fastest gyroscopically stable release at spin {base.spin_rpm:g} rpm is '
                f'about {speed:.2f} m/s (S_g = 1 at {critical:.2f} m/s air speed), below '
                f'max_speed {max_speed:g} m/s, and it does not reach the target: {exc}',
                'gyroscopic_stability', exc.closest) from None
    raise PlanError(
        f'no gyroscopically stable release at spin {base.spin_rpm:g} rpm found up to '
        f'max_speed {max_speed:g} m/s', 'gyroscopic_stability')


def _plan(target, base, objective, max_speed, elevation_range, receiver, arrival_time,
          arrival_window, attitude, step, tolerance, wobble) -> Plan:
    """Return :func:`plan` of one objective and attitude, as asked (no comparison)."""
    base = base or Release()
    if objective not in OBJECTIVES:
        raise PlanError(f"unknown objective '{objective}' (known: {', '.join(OBJECTIVES)})",
                        'objective')
    if attitude not in ATTITUDES:
        raise PlanError(f"unknown attitude '{attitude}' (known: {', '.join(ATTITUDES)})",
                        'attitude')
    max_speed = _number('max_speed', max_speed, *LIMITS['speed'])
    lo_e = _number('elevation_range[0]', elevation_range[0], *LIMITS['elevation_deg'])
    hi_e = _number('elevation_range[1]', elevation_range[1], *LIMITS['elevation_deg'])
    if lo_e >= hi_e:
        raise PlanError('elevation_range must be increasing', 'elevation_range')
    tolerance = _number('tolerance', tolerance, 1e-4, 10.0)
    for name, value in (('arrival_time', arrival_time),):
        if value is not None:
            _number(name, value, 0.05, 30.0)
    if arrival_window is not None:
        t0 = _number('arrival_window[0]', arrival_window[0], 0.0, 30.0)
        t1 = _number('arrival_window[1]', arrival_window[1], 0.0, 30.0)
        if t0 > t1:
            raise PlanError('arrival_window must be (earliest, latest)', 'arrival_window')
        arrival_window = (t0, t1)
    if (target is None) == (receiver is None):
        raise PlanError("give exactly one of 'target' and 'receiver'", 'target')
    if receiver is not None:
        _check_target(receiver.position, 'receiver.position')
        vel = np.asarray(receiver.velocity, dtype=float).reshape(-1)
        if vel.size != 3 or not np.all(np.isfinite(vel)) or np.any(np.abs(vel) > 20.0):
            raise PlanError("'receiver.velocity' must be 3 finite numbers within +-20 m/s",
                            'receiver.velocity')
        _number('receiver.time', receiver.time, -30.0, 30.0)
    sh = _Shooter(base, step)
    sh.mode = attitude if attitude in ('aligned', 'linear') else 'equilibrium'
    aim = _Aim(sh, max_speed, (lo_e, hi_e))

    def solve(point, guess=None):
        point = _check_target(point, 'target' if receiver is None else 'receiver position')
        sh.aim(point)
        if sh.distance < MIN_HORIZONTAL:
            raise PlanError(
                f'target is {sh.distance:.2f} m from the release point horizontally '
                f'(< {MIN_HORIZONTAL} m: the path would be near vertical)', 'min_horizontal')
        if arrival_time is not None:
            return aim.at_time(arrival_time, guess), 'timed'
        if objective == 'lowest_speed':
            return aim.lowest_speed(), 'lowest_speed'
        speed = max_speed if objective == 'fastest' else base.speed
        sol = aim.at_speed(speed, objective == 'lofted', guess)
        return sol, 'lofted' if objective == 'lofted' else 'flat'

    point = None if target is None else _check_target(target)
    sol, arc = None, 'flat'
    if receiver is None:
        sol, arc = solve(point)
    else:
        t_guess = arrival_time if arrival_time is not None else 1.0
        for _ in range(12):  # lead the receiver: aim at where it will be
            point = receiver.at(t_guess)
            sol, arc = solve(point, sol)
            if sol is None:
                break
            t_new = sh.cross(sol[0], sol[1], sol[2])
            if t_new is None:
                break
            speed_rx = float(np.linalg.norm(receiver.velocity))
            if abs(t_new[2] - t_guess) * speed_rx < 0.1 * SOLVE_TOLERANCE:
                break
            t_guess = t_new[2]
    if sol is not None and arrival_window is not None and arrival_time is None:
        t_arr = sh.cross(sol[0], sol[1], sol[2])
        if t_arr is not None and not arrival_window[0] <= t_arr[2] <= arrival_window[1]:
            wanted = min(max(t_arr[2], arrival_window[0]), arrival_window[1])
            return _plan(target, base, objective, max_speed, elevation_range, receiver, wanted,
                         None, attitude, step, tolerance, wobble)
    ok = sol is not None and _largest(sol[3]) <= SOLVE_TOLERANCE
    speed_used = max_speed if objective == 'fastest' else base.speed
    if not ok and arrival_time is not None:
        t_flat = _vacuum_time(max_speed, sh.distance, sh.height, sh.gravity)
        quickest = '' if t_flat is None else (
            f'; a flat arc at max_speed takes about {t_flat:.2f} s (vacuum estimate)')
        raise PlanError(
            f'no release within max_speed {max_speed:g} m/s and elevations [{lo_e:g}, '
            f'{hi_e:g}] deg arrives at the target {arrival_time:g} s after release{quickest}',
            'arrival_time', _closest_reachable(sh, max_speed, (lo_e, hi_e)))
    if not ok:
        fixed = arrival_time is None and objective in ('flat', 'lofted')
        limit_speed = speed_used if fixed else max_speed
        limit = 'speed' if fixed else 'max_speed'
        vacuum = None
        if fixed or objective == 'fastest':
            vacuum = _vacuum_elevation(limit_speed, sh.distance, sh.height, sh.gravity,
                                       objective == 'lofted')
        if vacuum is not None and not lo_e <= vacuum <= hi_e:
            raise PlanError(
                f'the {"lofted" if objective == "lofted" else "flat"} arc at {limit_speed:g} '
                f'm/s needs about {vacuum:.0f} deg elevation (vacuum estimate), outside '
                f'elevation_range [{lo_e:g}, {hi_e:g}] deg', 'elevation_range',
                _closest_reachable(sh, limit_speed, (lo_e, hi_e)))
        raise PlanError(
            f'target ({point[0]:.2f}, {point[1]:.2f}, {point[2]:.2f}) m is out of reach '
            f'at speed {limit_speed:g} m/s (limit {limit}) within elevations '
            f'[{lo_e:g}, {hi_e:g}] deg', limit, _closest_reachable(sh, limit_speed,
                                                                   (lo_e, hi_e)))
    speed, elev, azim = sol[0], sol[1], sol[2]
    if speed > max_speed * (1.0 + 1e-9):
        raise PlanError(
            f'the plan needs {speed:.2f} m/s > max_speed {max_speed:g} m/s', 'max_speed',
            _closest_reachable(sh, max_speed, (lo_e, hi_e)))
    if not lo_e - 1e-9 <= elev <= hi_e + 1e-9:
        raise PlanError(
            f'the plan needs elevation {elev:.2f} deg outside elevation_range '
            f'[{lo_e:g}, {hi_e:g}] deg', 'elevation_range',
            _closest_reachable(sh, speed, (lo_e, hi_e)))
    linear = _options(_direction(speed, elev, azim), *kernels.release_axis(
        sh.consts, sh.wind, _direction(speed, elev, azim), sh.h1, False))
    mode = attitude
    if attitude == 'refined':
        sh.offsets = _refine(sh, speed, elev, azim)
        resolved = _reaim(aim, sh, arc, speed, elev, azim, arrival_time, objective)
        if resolved is not None:
            speed, elev, azim = resolved
    return _checked_plan(sh, speed, elev, azim, mode, objective, arc, linear, tolerance, wobble)


def _number(name: str, value: Any, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise PlanError(f"'{name}' must be a number, got {type(value).__name__}", name)
    value = float(value)
    if not math.isfinite(value) or not lo <= value <= hi:
        raise PlanError(f"'{name}' = {value:g} must be finite and in [{lo:g}, {hi:g}]", name)
    return value


def _reaim(aim: _Aim, sh: _Shooter, arc, speed, elev, azim, arrival_time, objective):
    """Aim again with the refined attitude offsets (same objective, warm start)."""
    guess = (speed, elev, azim)
    if arrival_time is not None:
        sol = aim.at_time(arrival_time, guess)
    elif objective == 'lowest_speed':
        sol = aim._fixed_elevation(elev, speed, azim)
    else:
        sol = aim._fixed_speed(speed, elev, azim)
    if sol is None or _largest(sol[3]) > SOLVE_TOLERANCE:
        return None
    return sol[0], sol[1], sol[2]


REFINE_STEPS = np.array([0.05, 0.05, 0.5, 0.5])
"""Finite-difference steps of the refinement's four attitude offsets (deg, deg, deg/s, deg/s)."""


def _refine(sh: _Shooter, speed: float, elev: float, azim: float) -> np.ndarray:
    """
    Attitude offsets (deg, deg, deg/s, deg/s) minimising the nonlinear flight's wobble.

    The deviation of the axis from the equilibrium axis, d(t) = s(t) - X_p(t), answers the
    small offsets x of the release attitude linearly: d(t) = d0(t) + J(t) x, J by forward
    differences (4 flights beside the equilibrium release's). The offsets minimising
    max_t |d(t)| (the wobble amplitude, 2 sin(angle / 2)) on that model are found by SLSQP in
    epigraph form, then flown: kept if the flown wobble is below the equilibrium release's.
    """
    out = sh.cross(speed, elev, azim)
    until = out[2] if out is not None else sh.duration_guess(speed, elev)

    def deviation(offsets):
        sh.offsets = np.asarray(offsets, dtype=float)
        try:
            y0 = sh.y0(speed, elev, azim)
        except ReleaseError:
            return None
        times, states, _ = kernels.fly(y0, sh.step, sh.params, until, -1e4, sh.target, sh.d, -1)
        sh.flights += 1
        axis, eq = _axis_and_equilibrium(_wobble_samples(times, states), sh.params)
        return axis - eq

    start = np.zeros(4)
    base = deviation(start)
    columns = [deviation(h * np.eye(4)[i]) for i, h in enumerate(REFINE_STEPS)]
    if base is None or any(c is None for c in columns):
        sh.offsets = start
        return sh.offsets
    jac = np.stack([c - base for c in columns], axis=-1)  # (N, 3, 4), per step of REFINE_STEPS
    scale = float(np.max(np.linalg.norm(base, axis=-1)))
    if scale <= 0.0:
        sh.offsets = start
        return sh.offsets
    z = _minimax(base / scale, jac / scale)
    best = start
    if z is not None:
        trial = z * REFINE_STEPS
        flown = deviation(trial)
        if flown is not None and np.max(np.linalg.norm(flown, axis=-1)) < scale:
            best = trial
    sh.offsets = np.asarray(best, dtype=float)
    return sh.offsets


def _minimax(d0: np.ndarray, jac: np.ndarray) -> np.ndarray | None:
    """
    Return the x minimising max_n |d0[n] + jac[n] @ x| (d0 (N, 3), jac (N, 3, k)), or None.

    SLSQP in epigraph form (min s subject to s^2 >= |r_n|^2) on an active set: the largest
    residuals and every tenth sample first, then the samples the answer violates, until none.
    """
    from scipy.optimize import minimize

    n, k = jac.shape[0], jac.shape[2]
    norms = np.linalg.norm(d0, axis=-1)
    active = np.union1d(np.argsort(norms)[-20:], np.arange(0, n, 10))
    z = np.append(np.zeros(k), float(np.max(norms)))
    for _ in range(6):
        d, j = d0[active], jac[active]

        def constraint(z, d=d, j=j):
            r = d + j @ z[:k]
            return z[k] * z[k] - np.sum(r * r, axis=-1)

        def constraint_jac(z, d=d, j=j):
            r = d + j @ z[:k]
            return np.column_stack([-2.0 * np.einsum('nc,nck->nk', r, j),
                                    np.full(len(r), 2.0 * z[k])])

        res = minimize(lambda z: z[k], z, jac=lambda z: np.eye(k + 1)[k], method='SLSQP',
                       constraints=[{'type': 'ineq', 'fun': constraint, 'jac': constraint_jac}],
                       options={'maxiter': 100, 'ftol': 1e-12})
        if not np.all(np.isfinite(res.x)):
            return None
        z = res.x
        worst = np.linalg.norm(d0 + jac @ z[:k], axis=-1)
        over = np.nonzero(worst > abs(z[k]) * (1.0 + 1e-6))[0]
        if over.size == 0:
            break
        active = np.union1d(active, over[np.argsort(worst[over])[-20:]])
    return z[:k]


PAST_PLANE_STEPS = 2
"""Steps the checking flight goes on after it crosses the target plane (the closest approach
is within a step of the crossing; its interpolant needs the step after the closest sample)."""


def _checked_plan(sh: _Shooter, speed, elev, azim, mode, objective, arc, linear, tolerance,
                  with_wobble=True):
    """
    Build the Release, fly it as :class:`Flight` flies it and check the miss (module docstring).

    The checking flight starts from the Release's own state (:meth:`Release.initial_state`),
    passes the step rules of :func:`football_ros.physics.step_stability.check_flyable` and is
    flown by
    :func:`kernels.fly` (the real-time kernel's steps) to ``PAST_PLANE_STEPS`` past the target
    plane, or to its landing on z = 0, or 30 s (:func:`kernels.check_flight`, with its closest
    approach).
    """
    att, note = sh.attitude_note(speed, elev, azim)
    try:
        release = sh.base.replace(speed=speed, elevation_deg=elev,
                                  azimuth_deg=_wrap(azim), **att)
        initial = release.initial_state()
        largest_step = check_flyable(sh.params, initial, sh.step)
    except ReleaseError as exc:
        raise PlanError(f'the planned release is outside the release limits: {exc}',
                        'release') from None
    y_check = _state_vector(initial, sh.ball.inertia_ratio)
    times, states, miss, t_arr, point, n_keep, path_times, path_positions = (
        kernels.check_flight(y_check, sh.step, sh.params, sh.target, sh.d, PAST_PLANE_STEPS,
                             kernels.APPROACH_POINTS))
    sh.flights += 1
    if not miss <= tolerance:
        raise PlanError(
            f'the checking flight misses the target by {miss:.3f} m > tolerance '
            f'{tolerance:g} m', 'tolerance', point)
    wobble = delta = aligned_wobble = aligned_delta = math.nan
    if with_wobble:
        saved = sh.mode
        sh.mode = 'aligned'
        # The Release's own azimuth and spin: its velocity and h1 bit for bit.
        y0 = sh.y0(speed, elev, _wrap(azim), float(y_check[dyn.H1]))
        sh.mode = saved
        # The aligned release flown to the last checked row and both wobbles (:func:`wobble_of`
        # of the checking flight to the arrival and of the aligned one): one compiled call.
        step = aligned_step(sh.step, largest_step)
        wobble, delta, aligned_wobble, aligned_delta = (math.degrees(v) for v in (
            kernels.compare_wobbles(states, n_keep, y0, step, sh.params, sh.consts,
                                    _wobble_stride(sh.step), _wobble_stride(step),
                                    float(times[n_keep - 1]), sh.target, sh.d)))
        sh.flights += 1
    warnings = [note] if note and mode != 'aligned' else []
    # what simulate says of the same release (instability, the data ranges), to the arrival
    flight = Flight.from_release(release, sh.step)
    flown = flight.simulate(rate=100.0, duration=max(t_arr, sh.step))
    warnings += flight_warnings(release, flight.modes, flown.times, flown.aero_angles[:, 2],
                                flight.aero, flight.ball)
    return Plan(
        release=release,
        objective=objective,
        arc=arc,
        target=sh.target.copy(),
        arrival_time=t_arr,
        arrival_point=point,
        miss_m=miss,
        arrival_delta_deg=delta,
        wobble_deg=wobble,
        aligned_wobble_deg=aligned_wobble,
        aligned_arrival_delta_deg=aligned_delta,
        attitude=mode,
        linear_release={k: float(v) for k, v in linear.items()},
        flights=sh.flights,
        path_times=path_times,
        path_positions=path_positions,
        warnings=tuple(warnings),
    )


def _state_vector(initial: InitialState, inertia_ratio: float) -> np.ndarray:
    """Real-time state vector of a release state, as :class:`Flight` builds it."""
    y0 = np.zeros(dyn.N_STATE)
    y0[dyn.R:dyn.R + 3] = initial.position
    y0[dyn.V:dyn.V + 3] = initial.velocity
    y0[dyn.Q:dyn.Q + 4] = initial.attitude
    y0[dyn.H:dyn.H + 3] = initial.transverse_rate + inertia_ratio * initial.spin * initial.axis
    y0[dyn.H1] = inertia_ratio * initial.spin
    return y0


def _gyroscopically_stable(sh: _Shooter, initial: InitialState) -> bool:
    """Return the frozen linear theory's criterion at release (``LinearModes.stable``)."""
    air = _vec(initial.velocity)
    air = (air[0] - sh.wind[0], air[1] - sh.wind[1], air[2] - sh.wind[2])
    h1 = sh.ball.inertia_ratio * initial.spin
    return h1 * h1 > 4.0 * moment_slope(sh.ball, math.sqrt(_dot(air, air)))


def warm_up() -> None:
    """
    Load (or, on a cold numba cache, compile) the planner's kernels.

    One short plan with the refined attitude (which also aims and checks the equilibrium
    release) and :func:`wobble_of` of its release state.
    """
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    plan([12.0, 0.0, 1.5], base, attitude='refined')
    sh = _Shooter(base, DEFAULT_STEP)
    y0 = _state_vector(base.initial_state(), sh.ball.inertia_ratio)
    wobble_of(np.array([0.0, DEFAULT_STEP]), np.stack([y0, y0]), sh.params)


def _wrap(azim: float) -> float:
    return (azim + 180.0) % 360.0 - 180.0
