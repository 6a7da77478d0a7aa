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
The kernel's state and parameter layout and :func:`make_params` (numpy only, no numba).

:mod:`football_ros.physics.dynamics` integrates with these arrays; the linear theory, the McCoy
numbers and the flyability checks read them without loading the compiled kernels.
"""

from __future__ import annotations

import numpy as np

from .aero import AeroModel
from .frames import GRAVITY
from .presets import BallPreset

# State layout.
R, V, Q, H, H1, PHI = 0, 3, 6, 10, 13, 14
N_STATE = 15

# Parameter layout (make_params fills it; 0 coefficients switch terms off).
(
    P_MOMENT_K,
    P_SPIN_RATIO,
    P_GRAVITY,
    P_SIN2DELTA,
    P_FORCE_K,
    P_CD0,
    P_CD2,
    P_CLA,
    P_CNPA,
    P_DAMP_K,
    P_CMQ,
    P_CLP,
    P_CMPA,
    P_DIAMETER,
    P_WIND,
) = range(15)
N_PARAM = P_WIND + 3


def make_params(
    ball: BallPreset,
    moment: str = 'linear',
    aero: AeroModel | None = None,
    gravity: float = GRAVITY,
) -> np.ndarray:
    """
    Kernel parameters. ``aero`` None = the paper's model (torque only).

    k = rho S D C_Malpha / (2 I_t) [1/m^2], I_t/I_s, g [m/s^2], moment-curve flag, then the full
    model's rho S / (2 m) [1/m], coefficients, rho S D^2 / (2 I_t) [1/m], D [m] and wind [m/s].
    The density is the ball's (:func:`football_ros.physics.aero.resolve` sets the full model's).
    """
    params = np.zeros(N_PARAM)
    rho = ball.air_density
    area = ball.reference_area
    params[P_MOMENT_K] = ball.moment_coefficient()
    params[P_SPIN_RATIO] = 1.0 / ball.inertia_ratio
    params[P_GRAVITY] = gravity
    params[P_SIN2DELTA] = 1.0 if moment == 'sin2delta' else 0.0
    if aero is not None:
        params[P_FORCE_K] = rho * area / (2.0 * ball.mass)
        params[P_DAMP_K] = rho * area * ball.diameter**2 / (2.0 * ball.inertia_transverse)
        params[P_DIAMETER] = ball.diameter
        if aero.drag:
            params[P_CD0], params[P_CD2] = aero.c_d0, aero.c_d2
        if aero.lift:
            params[P_CLA] = aero.c_l_alpha
        if aero.magnus:
            params[P_CNPA], params[P_CMPA] = aero.c_n_p_alpha, aero.c_m_p_alpha
        if aero.pitch_damping:
            params[P_CMQ] = aero.c_m_q
        if aero.spin_damping:
            params[P_CLP] = aero.c_l_p
        params[P_WIND:P_WIND + 3] = aero.wind
    return params
