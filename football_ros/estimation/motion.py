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
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn

X_R, X_V, X_S, X_H, X_KD, X_KL = 0, 3, 6, 9, 12, 13
N_X = 14


@njit(cache=True)
def scaled(params: np.ndarray, kd: float, kl: float) -> np.ndarray:
    """Kernel parameters with drag (C_D0, C_D2) scaled by max(kd, 0) and lift by kl."""
    p = params.copy()
    kd = max(kd, 0.0)
    p[dyn.P_CD0] *= kd
    p[dyn.P_CD2] *= kd
    p[dyn.P_CLA] *= kl
    return p


@njit(cache=True)
def _load(point: np.ndarray, y: np.ndarray) -> None:
    """Point (N_X,) -> dynamics state (N_STATE,): s normalised, q_nr the shortest turn to s."""
    for j in range(6):
        y[dyn.R + j] = point[X_R + j]
    ns = math.sqrt(point[X_S] ** 2 + point[X_S + 1] ** 2 + point[X_S + 2] ** 2)
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
        p = scaled(params, points[i, X_KD], points[i, X_KL])
        _load(points[i], y)
        for _ in range(n):
            dyn.rk4_step_with(y, h, p, y, work)
        _store(y, points[i])


@njit(cache=True)
def land_points(
    points: np.ndarray, params: np.ndarray, step: float, ground: float, horizon: float
) -> np.ndarray:
    """
    Landing of each row of ``points`` (m, N_X) on z = ``ground``.

    (m, 4) rows of time from now [s], x, y [m] and 1.0 if it lands within ``horizon`` [s] (else
    NaN, NaN, NaN, 0.0).
    """
    out = np.full((points.shape[0], 4), np.nan)
    out[:, 3] = 0.0
    y = np.empty(dyn.N_STATE)
    nxt = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    n_max = int(math.ceil(horizon / step))
    for i in range(points.shape[0]):
        p = scaled(params, points[i, X_KD], points[i, X_KL])
        _load(points[i], y)
        if y[dyn.R + 2] <= ground:
            out[i, 0], out[i, 1], out[i, 2], out[i, 3] = 0.0, y[0], y[1], 1.0
            continue
        for k in range(n_max):
            dyn.rk4_step_with(y, step, p, nxt, work)
            if dyn.crossed_ground(y, nxt, ground):
                tau = dyn.landing_time_in_step(y, step, p, ground)
                dyn.rk4_step_with(y, tau, p, nxt, work)
                out[i, 0], out[i, 1], out[i, 2], out[i, 3] = k * step + tau, nxt[0], nxt[1], 1.0
                break
            y[:] = nxt
    return out


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
    ``horizon`` [s].
    """
    n_max = int(math.ceil(horizon / sample_dt)) + 1
    times = np.empty(n_max)
    pos = np.empty((n_max, 3))
    p = scaled(params, x[X_KD], x[X_KL])
    y = np.empty(dyn.N_STATE)
    _load(x, y)
    nxt = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    times[0] = 0.0
    pos[0] = y[:3]
    sub = max(1, int(math.ceil(sample_dt / step - 1e-9)))
    h = sample_dt / sub
    t = 0.0
    for k in range(1, n_max):
        for _ in range(sub):
            dyn.rk4_step_with(y, h, p, nxt, work)
            if dyn.crossed_ground(y, nxt, ground):
                tau = dyn.landing_time_in_step(y, h, p, ground)
                dyn.rk4_step_with(y, tau, p, nxt, work)
                times[k] = t + tau
                pos[k] = nxt[:3]
                pos[k, 2] = ground
                return times[: k + 1], pos[: k + 1]
            y[:] = nxt
            t += h
        times[k] = t
        pos[k] = y[:3]
    return times, pos
