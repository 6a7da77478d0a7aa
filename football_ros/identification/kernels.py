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
The fit's compiled flights: many states, each with its own kernel parameters, through one track.

A row is a state of :mod:`football_ros.physics.dynamics` at the track's first time, flown with
that module's step :func:`~football_ros.physics.dynamics.rk4_step_with` (no ground: a track
ends where its fixes end) and its own parameter row, so that a finite-difference Jacobian in
the release state and in the shared coefficients is one call per track.
"""

from __future__ import annotations

import math
import time

from numba import njit
import numpy as np

from ..physics import dynamics as dyn

N_OUT = 6
"""Columns per time of :func:`fly_rows`: position [m], then the unit spin axis (field)."""


@njit(cache=True)
def fly_rows(
    states: np.ndarray, params: np.ndarray, times: np.ndarray, step: float, out: np.ndarray
) -> None:
    """
    Fly each row of ``states`` (m, N_STATE), at time 0, through ``times`` (K,) [s] ascending.

    Row i flies with ``params[i]`` (m, N_PARAM) in RK4 steps of at most ``step`` [s]; ``out``
    (m, K, N_OUT) gets its position [m] and unit axis at each time. A row that cannot be flown
    (a zero division in a stage, or a non-finite state) is NaN throughout.
    """
    y = np.empty(dyn.N_STATE)
    work = np.empty((5, dyn.N_STATE))
    for i in range(states.shape[0]):
        y[:] = states[i]
        p = params[i]
        ok = True
        t = 0.0
        for k in range(times.size):
            dt = times[k] - t
            n = int(math.ceil(dt / step - 1e-9))
            try:
                for _ in range(n):
                    dyn.rk4_step_with(y, dt / n, p, y, work)
            except Exception:  # noqa: BLE001 - a zero division in a stage
                ok = False
            if not ok:
                break
            t = times[k]
            sx, sy, sz = dyn.axis_of(y)
            out[i, k, 0], out[i, k, 1], out[i, k, 2] = y[dyn.R], y[dyn.R + 1], y[dyn.R + 2]
            out[i, k, 3], out[i, k, 4], out[i, k, 5] = sx, sy, sz
        if not ok:
            out[i, :, :] = np.nan


def warm_up():
    """Load (or compile) :func:`fly_rows`; return a CompileStep."""
    from ..physics.precompile import CompileStep

    start = time.perf_counter()
    stats = fly_rows.stats
    hits, misses = sum(stats.cache_hits.values()), sum(stats.cache_misses.values())
    states = np.zeros((1, dyn.N_STATE))
    states[0, dyn.Q + 3] = 1.0
    states[0, dyn.V] = 10.0
    params = np.zeros((1, dyn.N_PARAM))
    params[0, dyn.P_SPIN_RATIO] = 1.0
    params[0, dyn.P_GRAVITY] = 9.81
    fly_rows(states, params, np.array([0.0, 0.01]), 1e-3, np.empty((1, 2, N_OUT)))
    hits, misses = sum(stats.cache_hits.values()) - hits, sum(stats.cache_misses.values()) - misses
    return CompileStep(
        'fit kernel (identification)', time.perf_counter() - start, hits, misses
    )
