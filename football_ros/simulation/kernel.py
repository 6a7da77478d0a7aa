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

:func:`rk4_step_into` is :func:`~football_ros.physics.dynamics.rk4_step` with the caller's
scratch rows instead of five arrays allocated per step (the allocations are most of a step's
cost); test/test_world.py checks that both give the same bits. Folding it into dynamics.py
(rk4_step taking optional scratch) would leave one RK4 step.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from ..physics import dynamics as dyn


@njit(cache=True, nogil=True)
def rk4_step_into(
    y: np.ndarray, dt: float, params: np.ndarray, out: np.ndarray, scratch: np.ndarray
) -> None:
    """
    One RK4 step of ``dt`` [s] from ``y`` into ``out`` (may alias ``y``), projected.

    Bit for bit :func:`football_ros.physics.dynamics.rk4_step`; ``scratch`` is (5, N_STATE).
    """
    n = y.size
    k1, k2, k3, k4, tmp = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    dyn.derivative(y, params, k1)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * dt * k1[i]
    dyn.derivative(tmp, params, k2)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * dt * k2[i]
    dyn.derivative(tmp, params, k3)
    for i in range(n):
        tmp[i] = y[i] + dt * k3[i]
    dyn.derivative(tmp, params, k4)
    for i in range(n):
        out[i] = y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    dyn._project(out)


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
            rk4_step_into(y, dt, p, nxt, scratch)
            if dyn.crossed_ground(y, nxt, ground):
                landed = True
                break
            y[:] = nxt
            done[b] += 1
        rest = dt if landed else times[b] - done[b] * dt
        rk4_step_into(y, rest, p, nxt, scratch)
        if landed or dyn.crossed_ground(y, nxt, ground):
            tau = dyn.landing_time_in_step(y, rest, p, ground)
            dyn.rk4_step(y, tau, p, nxt)
            nxt[dyn.R + 2] = ground
            landing_times[b] = done[b] * dt + tau
        out[b] = nxt
        described[b] = dyn.describe(out[b:b + 1], p)[0]
