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
one (the same :func:`~football_ros.physics.dynamics.rk4_step`, ground test and landing finder
of :mod:`football_ros.physics.dynamics`): whole steps are committed, the rest of the way to
the asked time is a partial step, a step that crosses the ground ends the flight at the
landing. Only the loop over the balls and their steps is compiled here, so that a world of
many balls costs one call per tick instead of a Python loop over balls and steps.

The steps are :func:`~football_ros.physics.dynamics.rk4_step_with` on one set of scratch rows
(allocating them per step was most of a step's cost).
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn


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
    nxt = np.empty(states.shape[1])
    scratch = np.empty((5, states.shape[1]))
    for b in range(states.shape[0]):
        y = states[b]
        p = params[b]
        dt = steps[b]
        landing_times[b] = np.nan
        target = int(math.floor(times[b] / dt + 1e-9))
        landed = False
        while done[b] < target:
            dyn.rk4_step_with(y, dt, p, nxt, scratch)
            if dyn.crossed_ground(y, nxt, ground):
                landed = True
                break
            y[:] = nxt
            done[b] += 1
        rest = dt if landed else times[b] - done[b] * dt
        dyn.rk4_step_with(y, rest, p, nxt, scratch)
        if landed or dyn.crossed_ground(y, nxt, ground):
            tau = dyn.landing_time_in_step(y, rest, p, ground)
            dyn.rk4_step_with(y, tau, p, nxt, scratch)
            nxt[dyn.R + 2] = ground
            landing_times[b] = done[b] * dt + tau
        out[b] = nxt
        described[b] = dyn.describe(out[b:b + 1], p)[0]


def warm_up():
    """Load (or compile) :func:`advance_many` now; returns a precompile.CompileStep."""
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
    advance_many(
        ball, np.zeros(1, dtype=np.int64), np.full(1, 1e-3), params, np.full(1, 2.0), 0.0,
        np.empty((1, dyn.N_STATE)), np.empty((1, dyn.N_DESCRIBE)), np.empty(1),
    )
    hits, misses = sum(stats.cache_hits.values()) - hits, sum(stats.cache_misses.values()) - misses
    return CompileStep(
        'many-ball kernel (simulator world)', time.perf_counter() - start, hits, misses
    )
