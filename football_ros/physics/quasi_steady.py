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
The quasi-steady linear theory frame by frame, compiled (numba).

:mod:`.linear_theory` keeps the theory in plain Python and numpy (the modes report loads no
numba); here its scalar functions are compiled as they stand, for the real-time frame
(:class:`QuasiSteadyTracker`: one call of :func:`quasi_steady_advance` a frame, which in Python
was most of the default ball's cost a frame beyond a spawned ball's) and the planner's kernels.
"""

from __future__ import annotations

import cmath
import math

from numba import njit
import numpy as np

from .linear_theory import (
    drift_of,
    drift_points,
    drifting_equilibrium_scalar,
    LinearModes,
    local_exponents_scalar,
    mode_amplitudes,
    scalar_constants,
)

exponents_compiled = njit(cache=True, error_model='numpy')(local_exponents_scalar)
drift_points_compiled = njit(cache=True, error_model='numpy')(drift_points)
drift_of_compiled = njit(cache=True, error_model='numpy')(drift_of)
"""The scalar theory compiled, for kernels: the quasi-steady frame's, the planner's."""


@njit(cache=True, error_model='numpy')
def quasi_steady_advance(consts: tuple, air, h1: float, t: float, memory: np.ndarray) -> complex:
    """
    Return x = s2 + i s3 of the quasi-steady theory at ``t`` [s], its integrals moved on to it.

    ``consts`` from :func:`scalar_constants`, ``air`` the air velocity [m/s] (3, ``field``),
    ``h1`` [rad/s]; ``memory`` (complex, 10; updated in place): the last sample's t, sigma_1,
    sigma_2, B and D_c, the two integrals (sigma +- the WKB drift, trapezoid rule), the mode
    amplitudes k1, k2 and D_c at release. A ``t`` not after the last leaves the integrals.
    Not finite once an unstable ball's theory overflows.
    """
    sig1, sig2, b, d_c, x_p = exponents_compiled(consts, air, h1)
    air_a, h1_a, air_b, h1_b = drift_points_compiled(consts, air, h1)
    x_p = drift_of_compiled(b, d_c, x_p, exponents_compiled(consts, air_a, h1_a)[4],
                            exponents_compiled(consts, air_b, h1_b)[4])[0]
    if t > memory[0].real:
        dt = t - memory[0].real
        drift = (b - memory[3]) * 0.5 * (1.0 / (2j * d_c) + 1.0 / (2j * memory[4]))
        memory[5] += 0.5 * dt * (sig1 + memory[1]) + drift
        memory[6] += 0.5 * dt * (sig2 + memory[2]) - drift
        memory[0], memory[1], memory[2], memory[3], memory[4] = t, sig1, sig2, b, d_c
    common = cmath.sqrt(memory[9] / d_c)
    return common * (memory[7] * cmath.exp(memory[5]) + memory[8] * cmath.exp(memory[6])) + x_p


class QuasiSteadyTracker:
    """
    The quasi-steady linear theory sample by sample (real time).

    Call :meth:`update` with non-decreasing times; the integrals advance by the trapezoid rule
    between calls, from the release (t = 0) on (:func:`quasi_steady_advance`).
    """

    def __init__(
        self, modes: LinearModes, params: np.ndarray, release_air_velocity: np.ndarray
    ) -> None:
        self.modes, self.params = modes, params
        self._consts = scalar_constants(params)
        sig1, sig2, b, d_c, x_p = local_exponents_scalar(
            self._consts, release_air_velocity, modes.h1
        )
        x_p, x_p_dot = drifting_equilibrium_scalar(
            self._consts, release_air_velocity, float(modes.h1), b, d_c, x_p
        )
        k1, k2 = mode_amplitudes(modes, sig1, sig2, x_p, x_p_dot)
        # t, sigma_1, sigma_2, B, D_c (the last sample), the two integrals, k1, k2, D_c(0)
        self._memory = np.array([0.0, sig1, sig2, b, d_c, 0.0, 0.0, k1, k2, d_c], dtype=complex)

    def update(self, t: float, air_velocity: np.ndarray, h1: float) -> np.ndarray:
        """
        Return alpha, beta [rad] of the quasi-steady theory at ``t`` [s] since release.

        NaN once an unstable ball's theory overflows.
        """
        x = quasi_steady_advance(self._consts, air_velocity, float(h1), float(t),
                                 self._memory)
        if not (math.isfinite(x.real) and math.isfinite(x.imag)):
            return np.full(2, np.nan)
        s2, s3 = min(1.0, max(-1.0, x.real)), min(1.0, max(-1.0, x.imag))
        s1 = math.sqrt(max(0.0, 1.0 - s2 * s2 - s3 * s3))
        return np.array([math.atan2(s2, s1), math.asin(s3)])
