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
The tracker's compiled motion model: sigma points flown on the package's own dynamics.

A point is the filter state (``N_X`` floats, :mod:`.tracker`): position r [m], velocity v
[m/s], unit spin axis s, modified angular momentum h = H / I_t [rad/s] and the drag and lift
scales kd, kl, all in ``field``. Each point is flown as a state of
:mod:`football_ros.physics.dynamics` (a non-rolling frame with body x = s, h1 = h.s, spin
angle 0: the ball is axisymmetric, so the spin angle does not enter the motion) with that
module's step :func:`~football_ros.physics.dynamics.rk4_step_with` and its landing search, the
drag and lift coefficients scaled by kd and kl.

The dynamics divide by the air speed and by |s|: a point at rest in the air or with a zero axis
(hostile fixes, a sigma point far out) is nudged to 1 um/s downwards through the air and to the
axis x, and a point whose flight still fails (a zero division in a stage, non-finite numbers)
comes out as NaN, never as an exception: the filter treats it as a failed prediction.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn

X_R, X_V, X_S, X_H, X_KD, X_KL = 0, 3, 6, 9, 12, 13
N_X = 14
X_W = 14
"""Optional horizontal wind states (x, y) [m/s], added to the parameters' wind: a point of
N_X_WIND = 16 floats carries them (the filter with ``wind_sigma`` > 0)."""
N_X_WIND = 16
NO_PLANE = np.zeros(4)
"""The vertical plane of :func:`fly_to_planes` that no ball crosses (a zero normal)."""


@njit(cache=True)
def point_params(params: np.ndarray, point: np.ndarray) -> np.ndarray:
    """Kernel parameters of one point: its drag and lift scales, and its wind if it has one."""
    p = scaled(params, point[X_KD], point[X_KL])
    if point.size >= N_X_WIND:
        p[dyn.P_WIND] += point[X_W]
        p[dyn.P_WIND + 1] += point[X_W + 1]
    return p


@njit(cache=True)
def scaled(params: np.ndarray, kd: float, kl: float) -> np.ndarray:
    """Kernel parameters with drag (C_D0, C_D2) scaled by max(kd, 0) and lift by kl."""
    p = params.copy()
    kd = max(kd, 0.0)
    p[dyn.P_CD0] *= kd
    p[dyn.P_CD2] *= kd
    p[dyn.P_CLA] *= kl
    return p


MIN_AIRSPEED = 1e-6
"""Air speed [m/s] below which a point is nudged downwards (the dynamics divide by it)."""


@njit(cache=True)
def _load(point: np.ndarray, y: np.ndarray, params: np.ndarray) -> bool:
    """
    Point (N_X,) -> dynamics state (N_STATE,): s normalised, q_nr the shortest turn to s.

    False if the point is not finite (``y`` is then unusable).
    """
    for j in range(point.size):
        if not math.isfinite(point[j]):
            return False
    for j in range(6):
        y[dyn.R + j] = point[X_R + j]
    ux = y[dyn.V] - params[dyn.P_WIND]
    uy = y[dyn.V + 1] - params[dyn.P_WIND + 1]
    uz = y[dyn.V + 2] - params[dyn.P_WIND + 2]
    if ux * ux + uy * uy + uz * uz < MIN_AIRSPEED * MIN_AIRSPEED:
        y[dyn.V + 2] = params[dyn.P_WIND + 2] - MIN_AIRSPEED
    ns = math.sqrt(point[X_S] ** 2 + point[X_S + 1] ** 2 + point[X_S + 2] ** 2)
    if ns < 1e-12:
        sx, sy, sz = 1.0, 0.0, 0.0
    else:
        sx, sy, sz = point[X_S] / ns, point[X_S + 1] / ns, point[X_S + 2] / ns
    # Rotation taking body x to s: axis x_hat x s = (0, -sz, sy), w = 1 + sx (then normalised).
    qx, qy, qz, qw = 0.0, -sz, sy, 1.0 + sx
    nq = math.sqrt(qy * qy + qz * qz + qw * qw)
    if nq < 1e-9:  # s = -x_hat: half a turn about z
        qx, qy, qz, qw, nq = 0.0, 0.0, 1.0, 0.0, 1.0
    y[dyn.Q], y[dyn.Q + 1], y[dyn.Q + 2], y[dyn.Q + 3] = qx / nq, qy / nq, qz / nq, qw / nq
    hx, hy, hz = point[X_H], point[X_H + 1], point[X_H + 2]
    y[dyn.H], y[dyn.H + 1], y[dyn.H + 2] = hx, hy, hz
    y[dyn.H1] = hx * sx + hy * sy + hz * sz
    y[dyn.PHI] = 0.0
    return True


@njit(cache=True)
def _store(y: np.ndarray, point: np.ndarray) -> None:
    """Dynamics state -> the point's r, v, s, h (kd, kl untouched)."""
    for j in range(6):
        point[X_R + j] = y[dyn.R + j]
    sx, sy, sz = dyn.axis_of(y)
    point[X_S], point[X_S + 1], point[X_S + 2] = sx, sy, sz
    point[X_H], point[X_H + 1], point[X_H + 2] = y[dyn.H], y[dyn.H + 1], y[dyn.H + 2]


@njit(cache=True)
def propagate_points(points: np.ndarray, dt: float, params: np.ndarray, step: float) -> None:
    """Advance each row of ``points`` (m, N_X) by ``dt`` [s] in place (RK4, steps <= ``step``)."""
    if dt <= 0.0:
        return
    n = max(1, int(math.ceil(dt / step - 1e-9)))
    h = dt / n
    y = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    for i in range(points.shape[0]):
        p = point_params(params, points[i])
        ok = _load(points[i], y, p)
        if ok:
            try:
                for _ in range(n):
                    dyn.rk4_step_with(y, h, p, y, work)
            except Exception:  # noqa: BLE001 - a zero division in a stage
                ok = False
        if ok:
            _store(y, points[i])
        else:
            points[i, :] = np.nan


@njit(cache=True)
def fly_through(
    points: np.ndarray, times: np.ndarray, params: np.ndarray, step: float, out: np.ndarray
) -> None:
    """
    Fly each row of ``points`` (m, N_X), a state at time 0, through ``times`` (K,) [s] in turn.

    ``out`` (m, K, 3) gets the positions [m] at those times; each row of ``points`` ends as the
    state at ``times[-1]``. Times may go back (RK4 steps of either sign, each at most ``step``
    long): a state is flown backwards to where a track began. A row that cannot be flown is NaN.
    """
    y = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    for i in range(points.shape[0]):
        p = point_params(params, points[i])
        ok = _load(points[i], y, p)
        t = 0.0
        for k in range(times.size):
            if not ok:
                break
            dt = times[k] - t
            n = int(math.ceil(abs(dt) / step - 1e-9))
            try:
                for _ in range(n):
                    dyn.rk4_step_with(y, dt / n, p, y, work)
            except Exception:  # noqa: BLE001 - a zero division in a stage
                ok = False
            t = times[k]
            for j in range(3):
                out[i, k, j] = y[dyn.R + j]
        if ok:
            _store(y, points[i])
        else:
            points[i, :] = np.nan
            out[i, :, :] = np.nan


def fly_state(x: np.ndarray, times: np.ndarray, params: np.ndarray, step: float) -> tuple:
    """
    Fly one state ``x`` (a point, time 0) through ``times`` (K,) [s] (:func:`fly_through`).

    Returns its state at ``times[-1]`` and its positions (K, 3) [m]; NaN if it cannot be flown.
    """
    point = np.array(x, dtype=float)[None, :]
    times = np.asarray(times, dtype=float)
    out = np.empty((1, times.size, 3))
    fly_through(point, times, params, step, out)
    return point[0], out[0]


@njit(cache=True)
def _through(y: np.ndarray, plane: np.ndarray) -> float:
    """Signed distance [m] of the ball past the vertical ``plane`` (px, py, nx, ny)."""
    return plane[2] * (y[0] - plane[0]) + plane[3] * (y[1] - plane[1])


@njit(cache=True)
def _plane_time_in_step(y: np.ndarray, dt: float, params: np.ndarray, plane: np.ndarray) -> float:
    """Time [s] in [0, dt] at which the step from ``y`` reaches the vertical plane (bisection)."""
    lo, hi = 0.0, dt
    tmp = np.empty(y.size)
    work = np.empty((5, y.size))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        dyn.rk4_step_with(y, mid, params, tmp, work)
        if _through(tmp, plane) < 0.0:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def fly_to_planes(
    points: np.ndarray,
    params: np.ndarray,
    step: float,
    height: float,
    ground: float,
    horizon: float,
    plane: np.ndarray,
) -> np.ndarray:
    """
    Fly each row of ``points`` (m, N_X) down to z = ``ground``, noting the planes on the way.

    One flight per point gives (m, 13) rows. Columns 0-3, the landing: time from now [s], x, y
    [m], 1.0 if it lands within ``horizon`` [s] (else NaN, NaN, NaN, 0.0). Columns 4-7, the next
    downward crossing of z = ``height`` [m] before the landing, in the same form (a point now
    below ``height`` must first rise above it; ``height`` <= ``ground`` or -inf: none). Columns
    8-12, the first crossing before the landing of the vertical plane ``plane`` = (px, py, nx,
    ny) through (px, py) [m] with horizontal unit normal (nx, ny), in the normal's direction:
    time, x, y, z, 1.0 (a point already on or past it, or a zero normal: none). A point already
    on or below the ground has landed now.
    """
    out = np.full((points.shape[0], 13), np.nan)
    out[:, 3] = 0.0
    out[:, 7] = 0.0
    out[:, 12] = 0.0
    y = np.empty(dyn.N_STATE)
    nxt = np.empty(dyn.N_STATE)
    at = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    n_max = int(math.ceil(horizon / step))
    for i in range(points.shape[0]):
        p = point_params(params, points[i])
        if not _load(points[i], y, p):
            continue
        if y[dyn.R + 2] <= ground:
            out[i, 0], out[i, 1], out[i, 2], out[i, 3] = 0.0, y[0], y[1], 1.0
            continue
        crossing = height > ground
        facing = (plane[2] != 0.0 or plane[3] != 0.0) and _through(y, plane) < 0.0
        try:
            for k in range(n_max):
                dyn.rk4_step_with(y, step, p, nxt, work)
                if crossing and dyn.crossed_ground(y, nxt, height):
                    tau = dyn.landing_time_in_step(y, step, p, height)
                    dyn.rk4_step_with(y, tau, p, at, work)
                    out[i, 4], out[i, 5], out[i, 6] = k * step + tau, at[0], at[1]
                    out[i, 7] = 1.0
                    crossing = False
                if facing and _through(nxt, plane) >= 0.0:
                    tau = _plane_time_in_step(y, step, p, plane)
                    dyn.rk4_step_with(y, tau, p, at, work)
                    if at[dyn.R + 2] >= ground:  # else it lands first, in this step
                        out[i, 8], out[i, 9], out[i, 10] = k * step + tau, at[0], at[1]
                        out[i, 11], out[i, 12] = at[2], 1.0
                    facing = False
                if dyn.crossed_ground(y, nxt, ground):
                    tau = dyn.landing_time_in_step(y, step, p, ground)
                    dyn.rk4_step_with(y, tau, p, nxt, work)
                    out[i, 0], out[i, 1], out[i, 2] = k * step + tau, nxt[0], nxt[1]
                    out[i, 3] = 1.0
                    break
                y[:] = nxt
        except Exception:  # noqa: BLE001 - a zero division in a stage: no landing
            out[i, :] = np.nan
            out[i, 3] = 0.0
            out[i, 7] = 0.0
            out[i, 12] = 0.0
    return out


@njit(cache=True)
def _fly_path(
    y: np.ndarray,
    p: np.ndarray,
    times: np.ndarray,
    pos: np.ndarray,
    sample_dt: float,
    step: float,
    ground: float,
) -> int:
    """Fill ``times`` and ``pos`` from row 1 on from ``y``; return the number of rows used."""
    nxt = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    sub = max(1, int(math.ceil(sample_dt / step - 1e-9)))
    h = sample_dt / sub
    t = 0.0
    for k in range(1, times.size):
        for _ in range(sub):
            dyn.rk4_step_with(y, h, p, nxt, work)
            if dyn.crossed_ground(y, nxt, ground):
                tau = dyn.landing_time_in_step(y, h, p, ground)
                dyn.rk4_step_with(y, tau, p, nxt, work)
                times[k] = t + tau
                pos[k] = nxt[:3]
                pos[k, 2] = ground
                return k + 1
            y[:] = nxt
            t += h
        times[k] = t
        pos[k] = y[:3]
    return times.size


@njit(cache=True)
def path_of(
    x: np.ndarray,
    params: np.ndarray,
    sample_dt: float,
    step: float,
    ground: float,
    horizon: float,
) -> tuple:
    """
    Return times (m,) [s] from now and positions (m, 3) [m] of the state ``x``'s path.

    Positions every ``sample_dt`` [s] from now until the ground (the last row is on it) or
    ``horizon`` [s]; one NaN row if the state cannot be flown.
    """
    n_max = int(math.ceil(horizon / sample_dt)) + 1
    times = np.empty(n_max)
    pos = np.empty((n_max, 3))
    p = point_params(params, x)
    y = np.empty(dyn.N_STATE)
    times[0] = 0.0
    if not _load(x, y, p):
        pos[0] = np.nan
        return times[:1], pos[:1]
    pos[0] = y[:3]
    used = -1
    try:
        used = _fly_path(y, p, times, pos, sample_dt, step, ground)
    except Exception:  # noqa: BLE001 - a zero division in a stage
        used = -1
    if used < 0:
        pos[0] = np.nan
        return times[:1], pos[:1]
    return times[:used], pos[:used]
