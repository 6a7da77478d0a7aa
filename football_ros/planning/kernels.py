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
The planner's compiled flights: the real-time kernel's RK4 steps, stopped at the target plane.

:func:`fly` takes the steps of :func:`football_ros.physics.dynamics.propagate` sampled at every
step (the same states: positions and velocities bit for bit, the attitude to round-off, as
``propagate`` takes a zero-length projected step for each sample) without the per-sample
partial step, and can stop a few steps after the path first crosses the target plane
(p - T).d = 0 moving forward. :func:`plane_crossing` and :func:`closest_approach` locate the
crossing and the closest approach to T on the cubic Hermite interpolant of the steps
(:func:`football_ros.physics.batch.hermite`, the one interpolant).
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn
from ..physics import quasi_steady as qs
from ..physics.batch import hermite

APPROACH_POINTS = np.linspace(0.0, 1.0, 201)
"""Fractions of a step at which :func:`closest_approach` evaluates the interpolant."""

# The linear theory's plain-float functions, compiled there (one source and one cache each).
_exponents = qs.exponents_compiled
_drift_points = qs.drift_points_compiled
_drift_of = qs.drift_of_compiled


@njit(cache=True, nogil=True)
def fly(y0, dt, params, duration, ground, target, d, past_plane):
    """
    RK4 steps of ``dt`` [s] from ``y0`` (real-time state vector); return (times, states, landed).

    States at t = k dt for k = 0 .. floor(duration / dt) (as ``dynamics.propagate`` with
    sample period dt), or to the landing on z = ``ground`` (the last state then the landing,
    located as ``propagate`` locates it). ``past_plane`` >= 0: stop that many steps after the
    first state with (p - target).d >= 0 (a forward crossing of the target plane; ``target``,
    ``d`` (3,) in ``field``); < 0: never.
    """
    n_max = int(math.floor(duration / dt + 1e-9)) + 1
    times = np.empty(n_max)
    states = np.empty((n_max, y0.size))
    y = y0.copy()
    work = np.empty((5, y0.size))
    times[0] = 0.0
    states[0] = y0
    dyn.project_invariants(states[0])  # propagate's first sample: a zero-length projected step
    left = -1
    if past_plane >= 0:
        f = (y0[dyn.R] - target[0]) * d[0] + (y0[dyn.R + 1] - target[1]) * d[1] + (
            y0[dyn.R + 2] - target[2]) * d[2]
        if f >= 0.0:
            left = past_plane
    for k in range(1, n_max):
        if left == 0:
            return times[:k], states[:k], False
        dyn.rk4_step_with(y, dt, params, states[k], work)
        if dyn.crossed_ground(y, states[k], ground):
            times[k] = (k - 1) * dt + dyn.finish(y, dt, params, ground, True, states[k], work)
            return times[:k + 1], states[:k + 1], True
        y[:] = states[k]
        times[k] = k * dt
        if left > 0:
            left -= 1
        elif past_plane >= 0:
            f = (y[dyn.R] - target[0]) * d[0] + (y[dyn.R + 1] - target[1]) * d[1] + (
                y[dyn.R + 2] - target[2]) * d[2]
            if f >= 0.0:
                left = past_plane
    return times, states, False


@njit(cache=True)
def _along(p0, v0, p1, v1, dt, u, target, d):
    """(Hermite position at u - target).d."""
    out = 0.0
    for i in range(3):
        out += (hermite(p0[i], v0[i], p1[i], v1[i], dt, u) - target[i]) * d[i]
    return out


@njit(cache=True)
def plane_crossing(times, states, target, d):
    """
    First forward crossing of the plane (p - target).d = 0: (found, time [s], position (3,)).

    Newton on the cubic Hermite interpolant of the along-plane coordinate inside the step
    (8 iterations at most, forward-difference slope).
    """
    n = times.size
    k = -1
    for j in range(n):
        f = 0.0
        for i in range(3):
            f += (states[j, dyn.R + i] - target[i]) * d[i]
        if f >= 0.0:
            k = j - 1
            break
    point = np.zeros(3)
    if k < 0:
        return False, 0.0, point
    dt = times[k + 1] - times[k]
    p0, p1 = states[k, dyn.R:dyn.R + 3], states[k + 1, dyn.R:dyn.R + 3]
    v0, v1 = states[k, dyn.V:dyn.V + 3], states[k + 1, dyn.V:dyn.V + 3]
    f0, f1 = 0.0, 0.0
    for i in range(3):
        f0 += (p0[i] - target[i]) * d[i]
        f1 += (p1[i] - target[i]) * d[i]
    u = f0 / (f0 - f1) if f1 != f0 else 0.0
    for _ in range(8):
        val = _along(p0, v0, p1, v1, dt, u, target, d)
        du = 1e-6
        slope = (_along(p0, v0, p1, v1, dt, u + du, target, d) - val) / du
        if slope == 0.0:
            break
        step = val / slope
        u = min(max(u - step, 0.0), 1.0)
        if abs(step) < 1e-12:
            break
    for i in range(3):
        point[i] = hermite(p0[i], v0[i], p1[i], v1[i], dt, u)
    return True, times[k] + u * dt, point


@njit(cache=True)
def closest_approach(times, states, target, fractions):
    """
    Closest approach of sampled states to ``target``: (distance [m], time [s], point (3,)).

    The closest sample, then the cubic Hermite interpolant at ``fractions`` of each of the two
    steps beside it.
    """
    n = times.size
    k = 0
    best = math.inf
    for j in range(n):
        dist = 0.0
        for i in range(3):
            dist += (states[j, dyn.R + i] - target[i]) ** 2
        dist = math.sqrt(dist)
        if dist < best:
            best, k = dist, j
    point = states[k, dyn.R:dyn.R + 3].copy()
    t_best = times[k]
    trial = np.empty(3)
    for j in (k - 1, k):
        if j < 0 or j + 1 >= n:
            continue
        dt = times[j + 1] - times[j]
        for u in fractions:
            dist = 0.0
            for i in range(3):
                trial[i] = hermite(states[j, dyn.R + i], states[j, dyn.V + i],
                                   states[j + 1, dyn.R + i], states[j + 1, dyn.V + i], dt, u)
                dist += (trial[i] - target[i]) ** 2
            dist = math.sqrt(dist)
            if dist < best:
                best, t_best = dist, times[j] + u * dt
                point[:] = trial
    return best, t_best, point


@njit(cache=True, error_model='numpy')
def equilibrium_axes(states, params, consts):
    """
    Return the spin axes and the equilibrium axes X_p (unit, (N, 3), ``field``) of state rows.

    ``states`` (N, N_STATE) of the real-time kernel, ``params`` its parameters,
    ``consts`` = :func:`football_ros.physics.linear_theory.scalar_constants` of them. X_p: the
    drifting equilibrium x_p + B x_p' / C (:func:`~football_ros.physics.linear_theory.
    drifting_equilibrium_scalar`, compiled) against the local air velocity v - wind, at the
    row's h1, in the velocity frame of that air velocity (s1 = sqrt(1 - |X_p|^2)). NaN where
    the theory has no equilibrium.
    """
    n = states.shape[0]
    axes = np.empty((n, 3))
    eqs = np.empty((n, 3))
    for k in range(n):
        axes[k, 0], axes[k, 1], axes[k, 2] = dyn.axis_of(states[k])
        eqs[k, 0], eqs[k, 1], eqs[k, 2] = _local_equilibrium_axis(states[k], params, consts)
    return axes, eqs


@njit(cache=True, error_model='numpy')
def wobble(states, rows, params, consts):
    """
    Return (wobble amplitude, delta at the last row) [rad] over the state rows ``rows``.

    The largest angle between the spin axis and X_p (:func:`equilibrium_axes`; NaN if any is
    NaN) and the angle between the axis and the air velocity at ``rows[-1]`` (delta of
    :func:`football_ros.physics.dynamics.describe`); NaN, NaN without rows.
    """
    largest = 0.0 if rows.size else math.nan
    for k in rows:
        angle = _wobble_angle(states[k], params, consts)
        if math.isnan(angle) or angle > largest:
            largest = angle
            if math.isnan(angle):
                break
    if not rows.size:
        return largest, math.nan
    return largest, _delta(states[rows[-1]], params)


@njit(cache=True, error_model='numpy')
def _wobble_every(states, n, stride, params, consts, eqs, reuse, other, n_other, n_grid,
                  other_stride):
    """
    Return :func:`wobble` over the rows 0, ``stride``, 2 ``stride``, ... < ``n`` and n - 1.

    (The rows of :func:`football_ros.planning.planner._wobble_rows`, without their array.)
    X_p of the rows j ``stride`` is kept in or reused from ``eqs``. ``reuse`` False: X_p of row
    j stride is written to ``eqs[j]`` (if it has that row). True:
    ``eqs[j]`` holds X_p of row j ``other_stride`` of ``other`` (its first ``n_other`` rows, at
    the same time as row j stride of these ``n_grid`` evenly stepped ones) and is taken where
    this row's velocity and h1 agree with other's row to 1e-12 (relative): X_p depends on
    nothing else of a state, and no further than that on them.
    """
    if n <= 0:
        return math.nan, math.nan
    least = 1.0  # the smallest cosine: acos decreases, the largest angle is acos(least)
    k = 0
    while True:
        y = states[k]
        j = k // stride
        on_grid = k == j * stride
        if reuse and on_grid and k < n_grid and j * other_stride < n_other and _same_air(
                y, other[j * other_stride]):
            q = (eqs[j, 0], eqs[j, 1], eqs[j, 2])
        else:
            q = _local_equilibrium_axis(y, params, consts)
            if not reuse and on_grid and j < eqs.shape[0]:
                eqs[j, 0], eqs[j, 1], eqs[j, 2] = q
        cosine = _cosine(y, q)
        if math.isnan(cosine) or cosine < least:
            least = cosine
            if math.isnan(cosine):
                break
        if k == n - 1:
            break
        k = min(k + stride, n - 1)
    return math.acos(least), _delta(states[n - 1], params)


@njit(cache=True)
def _same_air(y, z):
    """Tell whether two states' velocities and h1 agree to 1e-12 (relative)."""
    for i in (dyn.V, dyn.V + 1, dyn.V + 2, dyn.H1):
        if not abs(y[i] - z[i]) <= 1e-12 * (1.0 + abs(z[i])):
            return False
    return True


@njit(cache=True, error_model='numpy')
def compare_wobbles(states, n, y0_aligned, dt_aligned, params, consts, stride, stride_aligned,
                    t_last, target, d):
    """
    Return the wobble comparison of a checked plan [rad]: (wobble, delta, aligned ones).

    :func:`_wobble_every` of the first ``n`` rows of the checking flight's ``states`` (evenly
    stepped, the last at ``t_last`` [s]) and of the aligned release ``y0_aligned`` flown by
    :func:`fly` in steps of ``dt_aligned`` [s] (ground z = 0) to ``t_last``, the last step a
    partial one to it. Where the two flights share a row's velocity and spin (the paper's
    centre flies the same parabola whatever the attitude and the step) X_p is computed once.
    """
    eqs = np.empty((max(n, 0) // stride + 1, 3))
    wob, delta = _wobble_every(states, n, stride, params, consts, eqs, False, states, 0, 0, 1)
    a_times, a_states, landed = fly(y0_aligned, dt_aligned, params, t_last, 0.0, target, d, -1)
    n_grid = a_times.size
    if not landed and a_times[n_grid - 1] < t_last - 1e-12:  # the partial step to t_last
        rows = np.empty((n_grid + 1, a_states.shape[1]))
        rows[:n_grid] = a_states
        dyn.rk4_step_with(a_states[n_grid - 1], t_last - a_times[n_grid - 1], params,
                          rows[n_grid], np.empty((5, rows.shape[1])))
        a_states = rows
    elif landed:
        n_grid -= 1  # the landing row is not on the step grid
    a_wob, a_delta = _wobble_every(a_states, a_states.shape[0], stride_aligned, params, consts,
                                   eqs, True, states, n, n_grid, stride)
    return wob, delta, a_wob, a_delta


@njit(cache=True, error_model='numpy')
def _cosine(y, q):
    """Cosine of the angle between the spin axis of a state and ``q`` (unit), in [-1, 1]."""
    sx, sy, sz = dyn.axis_of(y)
    return min(1.0, max(-1.0, sx * q[0] + sy * q[1] + sz * q[2]))


@njit(cache=True, error_model='numpy')
def _wobble_angle(y, params, consts):
    """Angle [rad] between the spin axis and X_p of one state (NaN without X_p)."""
    return math.acos(_cosine(y, _local_equilibrium_axis(y, params, consts)))


@njit(cache=True, error_model='numpy')
def _delta(y, params):
    """Angle [rad] between the spin axis and the air velocity of one state."""
    air = (y[dyn.V] - params[dyn.P_WIND], y[dyn.V + 1] - params[dyn.P_WIND + 1],
           y[dyn.V + 2] - params[dyn.P_WIND + 2])
    s1 = dyn.velocity_frame_components(air, dyn.axis_of(y))[0]
    return math.acos(min(1.0, max(-1.0, s1)))


@njit(cache=True, error_model='numpy')
def _local_equilibrium_axis(y, params, consts):
    """X_p of :func:`equilibrium_axes` for one state (a 3-tuple)."""
    air = (y[dyn.V] - params[dyn.P_WIND], y[dyn.V + 1] - params[dyn.P_WIND + 1],
           y[dyn.V + 2] - params[dyn.P_WIND + 2])
    h1 = y[dyn.H1]
    _, _, b, d_c, x_p = _exponents(consts, air, h1)
    air_a, h1_a, air_b, h1_b = _drift_points(consts, air, h1)
    x_eq = _drift_of(b, d_c, x_p, _exponents(consts, air_a, h1_a)[4],
                     _exponents(consts, air_b, h1_b)[4])[0]
    speed = math.sqrt(air[0] * air[0] + air[1] * air[1] + air[2] * air[2])
    e1x, e1y, e1z = air[0] / speed, air[1] / speed, air[2] / speed
    e2x, e2y, e2z = -e1z * e1x, -e1z * e1y, 1.0 - e1z * e1z
    n2 = math.sqrt(e2x * e2x + e2y * e2y + e2z * e2z)
    e2x, e2y, e2z = e2x / n2, e2y / n2, e2z / n2
    e3x, e3y, e3z = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    size = abs(x_eq)
    s1 = math.sqrt(max(0.0, 1.0 - size * size))
    qx = s1 * e1x + x_eq.real * e2x + x_eq.imag * e3x
    qy = s1 * e1y + x_eq.real * e2y + x_eq.imag * e3y
    qz = s1 * e1z + x_eq.real * e2z + x_eq.imag * e3z
    norm = math.sqrt(qx * qx + qy * qy + qz * qz)
    return qx / norm, qy / norm, qz / norm


@njit(cache=True, error_model='numpy')
def release_axis(consts, wind, velocity, h1, drift):
    """
    Return the least-wobble release axis (unit) and its rate [1/s] in ``field`` (3-tuples).

    The axis on the local equilibrium X_p against the air, turning with the velocity frame
    (w_V = -g cos(Phi) / U about e3) and with X_p' (K1 = K2 = 0 in the quasi-steady theory).
    ``consts`` = :func:`~football_ros.physics.linear_theory.scalar_constants`, ``wind`` and
    ``velocity`` [m/s] 3-tuples in ``field``, ``h1`` = (I_s/I_t) p [rad/s]; ``drift``: with the
    equilibrium's drift x_p + B x_p' / C and x_p' (:func:`~football_ros.physics.linear_theory.
    drifting_equilibrium_scalar`, compiled), else the frozen theory's C1 = C2 = 0 release
    (x_p = -F/C, not turning with it; for the paper's model the axis at the equilibrium
    sideslip s3p, turning at w_V).
    """
    air = (velocity[0] - wind[0], velocity[1] - wind[1], velocity[2] - wind[2])
    _, _, b, d_c, x_p = _exponents(consts, air, h1)
    x_p_dot = 0j
    if drift:
        air_a, h1_a, air_b, h1_b = _drift_points(consts, air, h1)
        x_p, x_p_dot = _drift_of(b, d_c, x_p, _exponents(consts, air_a, h1_a)[4],
                                 _exponents(consts, air_b, h1_b)[4])
    speed = math.sqrt(air[0] * air[0] + air[1] * air[1] + air[2] * air[2])
    e1x, e1y, e1z = air[0] / speed, air[1] / speed, air[2] / speed
    horizontal = math.hypot(air[0], air[1])
    e2x, e2y, e2z = -e1z * air[0] / horizontal, -e1z * air[1] / horizontal, horizontal / speed
    e3x, e3y, e3z = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    s1 = math.sqrt(max(0.0, 1.0 - abs(x_p) ** 2))
    ax = s1 * e1x + x_p.real * e2x + x_p.imag * e3x
    ay = s1 * e1y + x_p.real * e2y + x_p.imag * e3y
    az = s1 * e1z + x_p.real * e2z + x_p.imag * e3z
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / norm, ay / norm, az / norm
    omega_v = -consts[9] * horizontal / speed / speed
    tx, ty, tz = e3y * az - e3z * ay, e3z * ax - e3x * az, e3x * ay - e3y * ax
    rx = omega_v * tx + x_p_dot.real * e2x + x_p_dot.imag * e3x
    ry = omega_v * ty + x_p_dot.real * e2y + x_p_dot.imag * e3y
    rz = omega_v * tz + x_p_dot.real * e2z + x_p_dot.imag * e3z
    along = rx * ax + ry * ay + rz * az
    return (ax, ay, az), (rx - along * ax, ry - along * ay, rz - along * az)


@njit(cache=True)
def release_options(velocity, axis, rate):
    """
    Return the release options (alpha0, beta0 [deg], their rates [deg/s]) of an axis.

    :func:`football_ros.planning.planner._options` in plain floats: ``axis`` (unit) and its
    ``rate`` [1/s] in ``field``, angles against ``velocity`` [m/s] (its velocity frame); all
    3-tuples.
    """
    norm = math.sqrt(velocity[0] * velocity[0] + velocity[1] * velocity[1]
                     + velocity[2] * velocity[2])
    e1x, e1y, e1z = velocity[0] / norm, velocity[1] / norm, velocity[2] / norm
    ux, uy, uz = -e1z * e1x, -e1z * e1y, 1.0 - e1z * e1z  # UP - (UP.e1) e1
    norm = math.sqrt(ux * ux + uy * uy + uz * uz)
    e2x, e2y, e2z = ux / norm, uy / norm, uz / norm
    e3x, e3y, e3z = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    alpha = math.atan2(axis[0] * e2x + axis[1] * e2y + axis[2] * e2z,
                       axis[0] * e1x + axis[1] * e1y + axis[2] * e1z)
    beta = math.asin(min(1.0, max(-1.0, axis[0] * e3x + axis[1] * e3y + axis[2] * e3z)))
    c1 = rate[0] * e1x + rate[1] * e1y + rate[2] * e1z
    c2 = rate[0] * e2x + rate[1] * e2y + rate[2] * e2z
    c3 = rate[0] * e3x + rate[1] * e3y + rate[2] * e3z
    ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
    d_alpha = c1 * (-cb * sa) + c2 * (cb * ca) + c3 * 0.0
    d_beta = c1 * (-sb * ca) + c2 * (-sb * sa) + c3 * cb
    return (math.degrees(alpha), math.degrees(beta), math.degrees(d_alpha / (cb * cb)),
            math.degrees(d_beta))


@njit(cache=True, nogil=True)
def check_flight(y0, dt, params, target, d, past_plane, fractions):
    """
    Fly the checking flight of a plan and find its closest approach to ``target``.

    :func:`fly` from ``y0`` (30 s at most, ground z = 0, stopped ``past_plane`` steps past the
    target plane), then :func:`closest_approach` (``fractions``). Returns (times, states,
    miss [m], arrival time [s], arrival point (3,), rows up to the arrival, path times and
    positions (rows up to the arrival, then the arrival itself)).
    """
    times, states, _ = fly(y0, dt, params, 30.0, 0.0, target, d, past_plane)
    miss, t_arr, point = closest_approach(times, states, target, fractions)
    n = 0
    while n < times.size and times[n] <= t_arr + 1e-12:  # times increase
        n += 1
    path_times = np.empty(n + 1)
    path_positions = np.empty((n + 1, 3))
    for k in range(n):
        path_times[k] = times[k]
        for i in range(3):
            path_positions[k, i] = states[k, dyn.R + i]
    path_times[n] = t_arr
    path_positions[n] = point
    return times, states, miss, t_arr, point, n, path_times, path_positions
