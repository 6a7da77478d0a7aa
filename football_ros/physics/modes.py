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
The modes of a flight as it is flown: one place for the linear modes and the stability numbers.

:func:`flown_model` gives the ball, aero settings and kernel parameters a release flies with
and :func:`flown_modes` the linear modes of those parameters (air-relative velocity, the
kernel's gravity); :class:`football_ros.physics.flight.Flight` and ``football-ros modes``
(:func:`modes_report`) both build their modes through these two functions. The stability
numbers (McCoy's factors and the package's own mode rates) are :func:`dynamic_stability`.
No numba: ``modes`` starts without the integrator.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from . import model_params as dyn
from .aero import AeroModel, resolve
from .linear_theory import linear_modes, LinearModes, mode_rates
from .presets import BallPreset
from .release import InitialState, Release


def flown_model(
    ball: BallPreset, model: str, moment: str, aero: AeroModel | None
) -> tuple[BallPreset, AeroModel | None, np.ndarray]:
    """
    Return the ball (with the model's air density), the aero settings and the kernel params.

    ``aero`` None and ``model`` 'paper' fly the torque-only model (no wind).
    """
    ball, aero = resolve(ball, model, aero)
    return ball, aero, dyn.make_params(ball, moment, aero)


def flown_modes(ball: BallPreset, initial: InitialState, params: np.ndarray) -> LinearModes:
    """
    Return the frozen linear modes of ``initial`` as flown with kernel ``params``.

    Against the air-relative velocity (the params' wind [m/s] in ``field``) and with the
    params' gravity [m/s^2].
    """
    return linear_modes(
        ball,
        initial,
        gravity=float(params[dyn.P_GRAVITY]),
        wind=params[dyn.P_WIND:dyn.P_WIND + 3].copy(),
    )


@dataclass(frozen=True)
class DynamicStability:
    """
    McCoy's stability factors and the modes' per-second rates, at one air speed and spin.

    s_g: gyroscopic stability factor P^2/(4M); s_d: dynamic stability factor 2T/H (McCoy's
    definition, per calibre); dynamically_stable: 1/S_g < S_d (2 - S_d);
    fast/slow_damping_rate [1/s]: the modes' amplitude rates in time (negative = the mode
    decays), fast/slow_frequency [rad/s]: their frequencies (fast = larger |frequency|; both
    negative for a left-handed spiral).
    """

    s_g: float
    s_d: float
    dynamically_stable: bool
    fast_damping_rate: float
    slow_damping_rate: float
    fast_frequency: float = math.nan
    slow_frequency: float = math.nan


def dynamic_stability(
    ball: BallPreset, speed: float, spin: float, model: AeroModel
) -> DynamicStability:
    """
    Return McCoy's S_g, S_d and the modes' per-second damping rates.

    At air speed ``speed`` [m/s] and ``spin`` [rad/s], for the terms switched on in ``model``
    (the ball's air density).

    S_g = P^2 / (4M), S_d = 2T/H with P = (I_s/I_t) p D / V, M = rho S D^3 C_Malpha / (2 I_t),
    H = rho S D / (2m) [C_Lalpha - C_D0 - (m D^2/I_t) C_Mq],
    T = rho S D / (2m) [C_Lalpha + (m D^2/I_s) C_Mpalpha] (the Magnus MOMENT).

    The rates are NOT McCoy's lambda V / D: his H holds -C_D0 because, per calibre, P is
    assumed constant (spin falling with speed), while a football's spin barely changes. They
    come from the time-domain equation with the WKB terms of the slowing flight (drag and spin
    damping): :func:`football_ros.physics.linear_theory.mode_rates` (docs/physics.md
    section 5), checked against rates measured in integrated flights.
    """
    mass, diameter, density, c_m_alpha = ball.mass, ball.diameter, ball.air_density, ball.c_m_alpha
    inertia_spin, inertia_transverse = ball.inertia_spin, ball.inertia_transverse
    area = math.pi * diameter**2 / 4.0
    p_nd = (inertia_spin / inertia_transverse) * spin * diameter / speed
    m_nd = density * area * diameter**3 / (2.0 * inertia_transverse) * c_m_alpha
    c_l = model.c_l_alpha if model.lift else 0.0
    c_d = model.c_d0 if model.drag else 0.0
    c_mpa = model.c_m_p_alpha if model.magnus else 0.0
    c_mq = model.c_m_q if model.pitch_damping else 0.0
    t_nd = (
        density
        * area
        * diameter
        / (2.0 * mass)
        * (c_l + mass * diameter**2 / inertia_spin * c_mpa)
    )
    h_nd = (
        density
        * area
        * diameter
        / (2.0 * mass)
        * (c_l - c_d - mass * diameter**2 / inertia_transverse * c_mq)
    )
    s_g = p_nd**2 / (4.0 * m_nd) if m_nd else math.inf
    s_d = 2.0 * t_nd / h_nd if h_nd else math.nan
    stable = bool(s_g > 1.0 and np.isfinite(s_d) and 1.0 / s_g < s_d * (2.0 - s_d))
    params = dyn.make_params(ball, 'linear', model)
    fast, slow = mode_rates(params, speed, ball.inertia_ratio * spin)
    return DynamicStability(s_g, s_d, stable, fast.real, slow.real, fast.imag, slow.imag)


def modes_report(release: Release) -> dict:
    """
    Linear-theory numbers of a release as plain data (rad, rad/s, rpm, 1/s).

    The ball, settings and modes :class:`football_ros.physics.flight.Flight` flies
    (:func:`flown_model`, :func:`flown_modes`), without importing the integrator (numba).
    """
    initial = release.initial_state()
    ball, aero, params = flown_model(
        release.preset(), release.model, release.moment, release.aero_model()
    )
    m = flown_modes(ball, initial, params)
    aero = aero or AeroModel().without_extras()
    stability = dynamic_stability(ball, m.speed, initial.spin, aero)
    return {
        'ball': release.ball,
        'speed': m.speed,
        'flight_path_angle': m.flight_path_angle,
        'm_alpha': m.m_alpha,
        'h1': m.h1,
        'omega_fast': m.omega_fast,
        'omega_slow': m.omega_slow,
        'growth_rate': m.growth_rate,
        'stable': m.stable,
        'gyroscopic_stability_factor': m.gyroscopic_stability_factor,
        'critical_spin_rpm': m.critical_spin_rpm,
        'equilibrium_sideslip': m.equilibrium_sideslip,
        'c1': [m.c1.real, m.c1.imag],
        'c2': [m.c2.real, m.c2.imag],
        'model': release.model,
        'dynamic_stability_factor': _finite_or_none(stability.s_d),
        'dynamically_stable': stability.dynamically_stable if release.model == 'full' else None,
        'fast_damping_rate': _finite_or_none(stability.fast_damping_rate),
        'slow_damping_rate': _finite_or_none(stability.slow_damping_rate),
    }


def _finite_or_none(value: float) -> float | None:
    return value + 0.0 if math.isfinite(value) else None  # + 0.0 turns -0.0 into 0.0
