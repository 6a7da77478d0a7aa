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
Many balls' fixed-step RK4 in one compiled call: the world's lock-step and real-time kernel.

Each ball is advanced exactly as :meth:`football_ros.physics.flight.Flight.state_at` advances
one (the same RK4 step, projection, ground test and landing finder of
:mod:`football_ros.physics.dynamics`): whole steps are committed, the rest of the way to the
asked time is a partial step, a step that crosses the ground ends the flight at the landing.

The whole steps of the balls with equal parameter rows run together, ``LANES`` balls at a
time in SIMD lanes (:func:`_lanes_step`: the ball index innermost, so that LLVM vectorises over
the balls); a ball leaves its lane at its last whole step or before the step that crosses the
ground, and the next ball of the group takes the lane. Groups of fewer than ``MIN_LANED``
balls step one by one. The lanes compute the same IEEE operations in the same order as
:func:`~football_ros.physics.dynamics.rk4_step_with` (no fast-math: no reassociation, no FMA), so
the results are bit for bit those of ``Flight`` (test/test_world.py compares them with ==).
The partial step, the landing and :func:`~football_ros.physics.dynamics.describe` are then
done per ball with the scalar functions of :mod:`football_ros.physics.dynamics`.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn

LANES = 16
"""Balls stepped together (two AVX-512 registers of doubles per state component)."""
MIN_LANED = 3
"""Groups of fewer balls step one by one (idle lanes would cost more than they save)."""
_N = dyn.N_STATE
# The lanes' work array is (planes, N_STATE * LANES): component c of lane j at c * LANES + j.
# One array with constant strides: LLVM sees that the planes do not overlap and vectorises
# over the lanes without run-time alias checks (separate arrays need too many such checks).
_Y, _NXT, _K1, _K2, _K3, _K4, _TMP, _DT = range(8)
_RX, _RY, _RZ = ((dyn.R + i) * LANES for i in range(3))
_VX, _VY, _VZ = ((dyn.V + i) * LANES for i in range(3))
_QX, _QY, _QZ, _QW = ((dyn.Q + i) * LANES for i in range(4))
_HX, _HY, _HZ = ((dyn.H + i) * LANES for i in range(3))
_H1, _PHI = dyn.H1 * LANES, dyn.PHI * LANES


@njit(cache=True, inline='always')
def _lanes_derivative(w, src, dst, p):
    """:func:`dynamics.derivative` of plane ``src`` of ``w`` into plane ``dst``, params ``p``."""
    for j in range(LANES):
        qx, qy, qz, qw = w[src, _QX + j], w[src, _QY + j], w[src, _QZ + j], w[src, _QW + j]
        sx = 1.0 - 2.0 * (qy * qy + qz * qz)  # dynamics.axis_of
        sy = 2.0 * (qx * qy + qw * qz)
        sz = 2.0 * (qx * qz - qw * qy)
        hx, hy, hz = w[src, _HX + j], w[src, _HY + j], w[src, _HZ + j]
        vx, vy, vz = w[src, _VX + j], w[src, _VY + j], w[src, _VZ + j]
        ax, ay, az, dhx, dhy, dhz, dh1 = dyn.loads(
            (vx, vy, vz), (sx, sy, sz), (hx, hy, hz), w[src, _H1 + j], p
        )
        hs = hx * sx + hy * sy + hz * sz
        wx, wy, wz = hx - hs * sx, hy - hs * sy, hz - hs * sz
        w[dst, _RX + j], w[dst, _RY + j], w[dst, _RZ + j] = vx, vy, vz
        w[dst, _VX + j], w[dst, _VY + j], w[dst, _VZ + j] = ax, ay, az
        w[dst, _QX + j] = 0.5 * (wx * qw + wy * qz - wz * qy)
        w[dst, _QY + j] = 0.5 * (-wx * qz + wy * qw + wz * qx)
        w[dst, _QZ + j] = 0.5 * (wx * qy - wy * qx + wz * qw)
        w[dst, _QW + j] = 0.5 * (-wx * qx - wy * qy - wz * qz)
        w[dst, _HX + j], w[dst, _HY + j], w[dst, _HZ + j] = dhx, dhy, dhz
        w[dst, _H1 + j] = dh1
        w[dst, _PHI + j] = p[dyn.P_SPIN_RATIO] * w[src, _H1 + j]


@njit(cache=True, inline='always')
def _lanes_step(w, p):
    """:func:`dynamics.rk4_step_with` of every lane (plane _Y, steps in _DT) into _NXT."""
    _lanes_derivative(w, _Y, _K1, p)
    for k in range(_N * LANES):
        w[_TMP, k] = w[_Y, k] + 0.5 * w[_DT, k] * w[_K1, k]
    _lanes_derivative(w, _TMP, _K2, p)
    for k in range(_N * LANES):
        w[_TMP, k] = w[_Y, k] + 0.5 * w[_DT, k] * w[_K2, k]
    _lanes_derivative(w, _TMP, _K3, p)
    for k in range(_N * LANES):
        w[_TMP, k] = w[_Y, k] + w[_DT, k] * w[_K3, k]
    _lanes_derivative(w, _TMP, _K4, p)
    for k in range(_N * LANES):
        w[_NXT, k] = w[_Y, k] + w[_DT, k] / 6.0 * (
            w[_K1, k] + 2.0 * w[_K2, k] + 2.0 * w[_K3, k] + w[_K4, k]
        )
    for j in range(LANES):  # dynamics._project
        qx, qy, qz, qw = w[_NXT, _QX + j], w[_NXT, _QY + j], w[_NXT, _QZ + j], w[_NXT, _QW + j]
        norm = math.sqrt(qx ** 2 + qy ** 2 + qz ** 2 + qw ** 2)
        qx, qy, qz, qw = qx / norm, qy / norm, qz / norm, qw / norm
        w[_NXT, _QX + j], w[_NXT, _QY + j], w[_NXT, _QZ + j], w[_NXT, _QW + j] = qx, qy, qz, qw
        sx = 1.0 - 2.0 * (qy * qy + qz * qz)
        sy = 2.0 * (qx * qy + qw * qz)
        sz = 2.0 * (qx * qz - qw * qy)
        hx, hy, hz = w[_NXT, _HX + j], w[_NXT, _HY + j], w[_NXT, _HZ + j]
        err = w[_NXT, _H1 + j] - (hx * sx + hy * sy + hz * sz)
        w[_NXT, _HX + j] = hx + err * sx
        w[_NXT, _HY + j] = hy + err * sy
        w[_NXT, _HZ + j] = hz + err * sz


@njit(cache=True, nogil=True, error_model='numpy')
def _whole_steps(states, done, steps, params, targets, members, ground, crossed):
    """
    Take the whole steps of the balls ``members`` (one parameter row ``params``) in lanes.

    Ball b goes from ``done[b]`` to ``targets[b]`` whole steps of ``steps[b]`` [s], or stops
    before the step that crosses ``ground`` (``crossed[b]`` = True); ``states`` and ``done``
    are updated in place. A lane that a ball leaves takes the next waiting ball; idle lanes
    step a copy of a state and are not read.
    """
    w = np.zeros((_DT + 1, _N * LANES))
    lane = np.full(LANES, -1, dtype=np.int64)
    rem = np.zeros(LANES, dtype=np.int64)
    hit = np.zeros(LANES, dtype=np.bool_)
    waiting = 0  # members[waiting:] have not had a lane yet
    while True:
        busy = 0
        for j in range(LANES):  # fill the idle lanes
            while lane[j] < 0 and waiting < members.size:
                b = members[waiting]
                waiting += 1
                if done[b] < targets[b]:
                    lane[j], rem[j] = b, targets[b] - done[b]
                    for i in range(_N):
                        w[_Y, i * LANES + j] = states[b, i]
                        w[_DT, i * LANES + j] = steps[b]
            busy += lane[j] >= 0
        if busy == 0:
            return
        for j in range(LANES):  # idle lanes step a copy of a busy one (never read back)
            if lane[j] < 0:
                first = 0
                while lane[first] < 0:
                    first += 1
                for i in range(_N):
                    w[_Y, i * LANES + j] = w[_Y, i * LANES + first]
                    w[_DT, i * LANES + j] = w[_DT, i * LANES + first]
        leaving = False
        while not leaving:  # step every lane until a ball leaves its lane
            _lanes_step(w, params)
            for j in range(LANES):
                hit[j] = lane[j] >= 0 and (
                    w[_Y, _RZ + j] >= ground
                    and w[_NXT, _RZ + j] <= ground
                    and w[_NXT, _VZ + j] < 0.0
                )
                leaving |= hit[j] or (lane[j] >= 0 and rem[j] == 1)
            for j in range(LANES):
                if not hit[j]:
                    rem[j] -= 1
            if not leaving:
                for k in range(_N * LANES):
                    w[_Y, k] = w[_NXT, k]
                continue
            for j in range(LANES):  # commit each lane, or let its ball leave
                b = lane[j]
                if b < 0:
                    continue
                if not hit[j]:
                    for i in range(_N):
                        w[_Y, i * LANES + j] = w[_NXT, i * LANES + j]
                if hit[j] or rem[j] == 0:
                    for i in range(_N):
                        states[b, i] = w[_Y, i * LANES + j]
                    done[b] = targets[b] - rem[j]
                    crossed[b] = hit[j]
                    lane[j] = -1


@njit(cache=True, nogil=True)
def advance_many(
    states: np.ndarray,
    done: np.ndarray,
    steps: np.ndarray,
    params: np.ndarray,
    times: np.ndarray,
    ground: float,
    out: np.ndarray,
    described: np.ndarray,
    landing_times: np.ndarray,
) -> None:
    """
    Advance ball b to ``times[b]`` [s] after its release.

    ``states`` (B, N_STATE): the committed state after ``done[b]`` whole steps of
    ``steps[b]`` [s] (both updated in place); ``params`` (B, N_PARAM). Writes ``out[b]``, the
    state at ``times[b]`` (or at the landing on z = ``ground``), ``described[b]`` its
    :func:`~football_ros.physics.dynamics.describe` row, and ``landing_times[b]`` the landing
    time [s] if the ball landed on the way (else NaN; a ball already landed is not passed).
    """
    n_balls = states.shape[0]
    targets = np.empty(n_balls, dtype=np.int64)
    for b in range(n_balls):
        targets[b] = int(math.floor(times[b] / steps[b] + 1e-9))
    crossed = np.zeros(n_balls, dtype=np.bool_)
    nxt = np.empty(states.shape[1])
    scratch = np.empty((5, states.shape[1]))
    # Groups of balls with equal parameter rows (the lanes share one row).
    group = np.full(n_balls, -1, dtype=np.int64)
    members = np.empty(n_balls, dtype=np.int64)
    for first in range(n_balls):
        if group[first] >= 0:
            continue
        group[first], members[0], count = first, first, 1  # (NaN parameters: a group of 1)
        for b in range(first + 1, n_balls):
            if group[b] < 0:
                same = True
                for k in range(params.shape[1]):
                    if params[b, k] != params[first, k]:
                        same = False
                        break
                if same:
                    group[b] = first
                    members[count] = b
                    count += 1
        if count >= MIN_LANED:
            _whole_steps(
                states, done, steps, params[first], targets, members[:count], ground, crossed
            )
            continue
        for b in members[:count]:  # as Flight.state_at
            done[b], crossed[b] = dyn.march(
                states[b], done[b], targets[b], steps[b], params[b], ground, nxt, scratch
            )
    for b in range(n_balls):  # the partial step, or the landing, per ball (as Flight.state_at)
        dt = steps[b]
        rest = dt if crossed[b] else times[b] - done[b] * dt
        tau = dyn.finish(states[b], rest, params[b], ground, crossed[b], out[b], scratch)
        landing_times[b] = np.nan if math.isnan(tau) else done[b] * dt + tau
        described[b] = dyn.describe(out[b:b + 1], params[b])[0]


@njit(cache=True)
def runaway_free(
    out: np.ndarray,
    described: np.ndarray,
    landing_times: np.ndarray,
    times: np.ndarray,
    bounds: np.ndarray,
    origins: np.ndarray,
    max_distance: float,
    max_time: float,
) -> np.ndarray:
    """
    Return, per ball of an :func:`advance_many` call, whether none of the runaway rules fires.

    The rules of :meth:`football_ros.simulation.world.FlightRun.runaway` on its results
    (``out``, ``described``, ``landing_times`` at ``times``): finite position, velocity and
    description; speed [m/s] and angular rate [rad/s] within ``bounds`` (B, 2); within
    ``max_distance`` [m] of ``origins`` (B, 3); landed or at most ``max_time`` [s] flown.
    """
    n = out.shape[0]
    fine = np.empty(n, dtype=np.bool_)
    for b in range(n):
        ok = True
        for i in range(3):
            ok = ok and math.isfinite(out[b, dyn.R + i]) and math.isfinite(out[b, dyn.V + i])
        for i in range(described.shape[1]):
            ok = ok and math.isfinite(described[b, i])
        if ok:
            vx, vy, vz = out[b, dyn.V], out[b, dyn.V + 1], out[b, dyn.V + 2]
            wx = described[b, dyn.D_OMEGA]
            wy = described[b, dyn.D_OMEGA + 1]
            wz = described[b, dyn.D_OMEGA + 2]
            dx = out[b, dyn.R] - origins[b, 0]
            dy = out[b, dyn.R + 1] - origins[b, 1]
            dz = out[b, dyn.R + 2] - origins[b, 2]
            landed = not math.isnan(landing_times[b])
            ok = (math.sqrt(vx * vx + vy * vy + vz * vz) <= bounds[b, 0]
                  and math.sqrt(wx * wx + wy * wy + wz * wz) <= bounds[b, 1]
                  and math.sqrt(dx * dx + dy * dy + dz * dz) <= max_distance
                  and (landed or times[b] <= max_time))
        fine[b] = ok
    return fine


def warm_up():
    """Load (or compile) :func:`advance_many` and :func:`runaway_free`; return a CompileStep."""
    import time

    from ..physics.precompile import CompileStep

    start = time.perf_counter()
    stats = advance_many.stats
    hits, misses = sum(stats.cache_hits.values()), sum(stats.cache_misses.values())
    ball = np.zeros((1, dyn.N_STATE))
    ball[0, dyn.Q + 3] = 1.0
    ball[0, dyn.R + 2] = 1.0
    ball[0, dyn.V] = 10.0
    params = np.zeros((1, dyn.N_PARAM))
    params[0, dyn.P_SPIN_RATIO] = 1.0
    params[0, dyn.P_GRAVITY] = 9.81
    out, described = np.empty((1, dyn.N_STATE)), np.empty((1, dyn.N_DESCRIBE))
    landing = np.empty(1)
    times = np.full(1, 2.0)
    advance_many(
        ball, np.zeros(1, dtype=np.int64), np.full(1, 1e-3), params, times, 0.0, out, described,
        landing,
    )
    runaway_free(out, described, landing, times, np.ones((1, 2)), np.zeros((1, 3)), 1.0, 1.0)
    hits, misses = sum(stats.cache_hits.values()) - hits, sum(stats.cache_misses.values()) - misses
    return CompileStep(
        'many-ball kernel (simulator world)', time.perf_counter() - start, hits, misses
    )
