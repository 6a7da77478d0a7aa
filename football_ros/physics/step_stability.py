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
Can a flight be integrated with its fixed step? The one check shared by every entry point.

Classical RK4 is stable for h * lambda inside its stability region: up to |h lambda| = 2.83 on
the imaginary axis (oscillations) and 2.79 on the negative real axis (damping). The fastest
rates of the equations of motion (:mod:`football_ros.physics.dynamics`), bounded over the whole
flight from the release, are:

- ``angular rate``: the fast (nutation) root of the linear theory, w^2 - h1 w + M = 0, bounded
  by (|h1| + sqrt(h1^2 + 4 M)) / 2 for stable and unstable balls alike, plus the transverse
  angular rate at release |w_perp|; M = M_alpha(U_max) (+ the Magnus-moment stiffness of the
  full model), U_max the largest air-relative speed the flight can reach:
  sqrt((V0 + |wind|)^2 + 2 g z0) (energy; drag only lowers it);
- ``pitch-damping rate`` (full model): |C_Mq| rho S D^2 U_max / (2 I_t);
- ``spin-damping rate`` (full model): |C_lp| rho S D^2 U_max / (2 I_s);
- ``drag and lift rate`` (full model): rho S U_max (2 C_D0 + 2 C_D2 + |C_Lalpha|) / (2 m)
  plus the Magnus-force rate rho S D |p| |C_Npalpha| / (2 m).

The spin itself does not limit the step: the spin angle grows at the constant rate p (torque
perpendicular to the axis keeps h1 constant), which RK4 integrates exactly; it enters only
through h1 and the full model's damping and Magnus terms above.

A flight is refused when step x rate exceeds :data:`MAX_STEP_RATE` for any of them: 1.0, a
third inside the stability boundary (the paper's model was measured to blow up near 2.8, see
test/test_step_stability.py). At 1.0 RK4 still damps an oscillation by 1.2 % per step; the default
step (1 ms) keeps the nominal passes below 0.04.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from . import dynamics as dyn
from .frames import GRAVITY
from .modes import check_air_speed, MIN_AIR_SPEED  # noqa: F401  (re-exported for batch)
from .release import InitialState, ReleaseError

MAX_STEP_RATE = 1.0
"""Largest accepted step x rate (dimensionless) for every rate of :func:`fastest_rates`."""


def max_air_speed(
    initial: InitialState, wind: Sequence[float] = (0.0, 0.0, 0.0), gravity: float = GRAVITY
) -> float:
    """Upper bound [m/s] of the air-relative speed over the flight (energy, no drag)."""
    speed = float(np.linalg.norm(initial.velocity)) + float(np.linalg.norm(wind))
    return math.sqrt(speed**2 + 2.0 * gravity * max(float(initial.position[2]), 0.0))


def fastest_rates(params: np.ndarray, initial: InitialState) -> dict[str, float]:
    """
    Return the rates [1/s] that limit the step, by name (module docstring).

    For kernel ``params`` (:func:`football_ros.physics.dynamics.make_params`) and the release
    state.
    """
    wind = params[dyn.P_WIND:dyn.P_WIND + 3]
    u_max = max_air_speed(initial, wind, params[dyn.P_GRAVITY])
    spin_ratio = params[dyn.P_SPIN_RATIO]  # I_t / I_s
    h1 = initial.spin / spin_ratio  # (I_s / I_t) p
    p = abs(initial.spin)
    damp = params[dyn.P_DAMP_K] * u_max  # rho S D^2 U / (2 I_t)
    stiffness = params[dyn.P_MOMENT_K] * u_max**2 + damp * p * abs(params[dyn.P_CMPA])
    angular = 0.5 * (abs(h1) + math.sqrt(h1 * h1 + 4.0 * stiffness))
    angular += float(np.linalg.norm(initial.transverse_rate))
    force_k = params[dyn.P_FORCE_K]  # rho S / (2 m)
    return {
        'angular rate': angular,
        'pitch-damping rate': damp * abs(params[dyn.P_CMQ]),
        'spin-damping rate': damp * abs(params[dyn.P_CLP]) * spin_ratio,
        'drag and lift rate': force_k
        * (
            u_max * (2.0 * params[dyn.P_CD0] + 2.0 * params[dyn.P_CD2] + abs(params[dyn.P_CLA]))
            + params[dyn.P_DIAMETER] * p * abs(params[dyn.P_CNPA])
        ),
    }


def check_flyable(params: np.ndarray, initial: InitialState, step: float) -> float:
    """
    Raise :class:`ReleaseError` naming the rate when ``step`` [s] is too large for it.

    Also refuses a release that moves with the wind (no air speed: the aerodynamic angles,
    the linear theory and the loads' direction are undefined). Returns the largest step [s]
    the rules allow this flight.
    """
    check_air_speed(initial, params)
    rates = fastest_rates(params, initial)
    for name, rate in rates.items():
        if not math.isfinite(rate):
            raise ReleaseError(f"the flight's {name} is not finite")
        if rate * step > MAX_STEP_RATE:
            raise ReleaseError(
                f"integration step {step:g} s is too large for this flight's {name} of "
                f'{rate:.4g} rad/s (step x rate = {rate * step:.3g} > {MAX_STEP_RATE:g}): '
                f'use a step <= {MAX_STEP_RATE / rate:.3g} s, or less spin, speed or moment'
            )
    return MAX_STEP_RATE / max(max(rates.values()), 1e-300)
