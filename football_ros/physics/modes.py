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
from .aero import AeroModel, max_valid_delta, out_of_validity, resolve
from .linear_theory import (
    angles_from_components,
    linear_modes,
    LinearModes,
    local_exponents,
    mode_rates,
)
from .presets import BallPreset
from .release import InitialState, Release, ReleaseError


def flown_model(
    ball: BallPreset, model: str, moment: str, aero: AeroModel | None
) -> tuple[BallPreset, AeroModel | None, np.ndarray]:
    """
    Return the ball (with the model's air density), the aero settings and the kernel params.

    ``aero`` None and ``model`` 'paper' fly the torque-only model (no wind).
    """
    ball, aero = resolve(ball, model, aero)
    return ball, aero, dyn.make_params(ball, moment, aero)


MIN_AIR_SPEED = 0.1
"""Smallest air speed [m/s] of a release: below it the angles and the modes are undefined."""


def check_air_speed(initial: InitialState, params: np.ndarray) -> None:
    """Raise :class:`ReleaseError` when the release moves with the params' wind."""
    air = initial.velocity - params[dyn.P_WIND:dyn.P_WIND + 3]
    if not float(np.linalg.norm(air)) > MIN_AIR_SPEED:
        raise ReleaseError(
            f'the release moves with the wind (air speed {np.linalg.norm(air):.3g} '
            f'm/s < {MIN_AIR_SPEED:g} m/s): its angle of attack is undefined'
        )


def flown_modes(ball: BallPreset, initial: InitialState, params: np.ndarray) -> LinearModes:
    """
    Return the frozen linear modes of ``initial`` as flown with kernel ``params``.

    Against the air-relative velocity (the params' wind [m/s] in ``field``) and with the
    params' gravity [m/s^2]; :func:`check_air_speed` first.
    """
    check_air_speed(initial, params)
    return linear_modes(
        ball,
        initial,
        gravity=float(params[dyn.P_GRAVITY]),
        wind=params[dyn.P_WIND:dyn.P_WIND + 3].copy(),
    )


@dataclass(frozen=True)
class DynamicStability:
    """
    The modes' per-second rates at one air speed and spin, and McCoy's reference factors.

    fast/slow_damping_rate [1/s]: the modes' amplitude rates in time (negative = the mode
    decays), fast/slow_frequency [rad/s]: their frequencies (fast = larger |frequency|; both
    negative for a left-handed spiral); dynamically_stable: gyroscopically stable and both
    rates negative (the package's own criterion). Reference numbers (McCoy, per calibre, spin
    falling with speed): s_g = P^2/(4M), s_d = 2T/H and mccoy_stable: 1/S_g < S_d (2 - S_d).
    """

    s_g: float
    s_d: float
    dynamically_stable: bool
    fast_damping_rate: float
    slow_damping_rate: float
    fast_frequency: float = math.nan
    slow_frequency: float = math.nan
    mccoy_stable: bool = False


def gyroscopic_stability(ball: BallPreset, speed: float, spin: float) -> float:
    """
    Return McCoy's gyroscopic stability factor S_g at air speed ``speed`` [m/s], ``spin`` [rad/s].

    S_g = P^2 / (4M), P = (I_s/I_t) p D / V, M = rho S D^3 C_Malpha / (2 I_t) (the ball's air
    density); inf without an overturning moment, 0 at zero spin; below 1 the ball may tumble.
    """
    diameter = ball.diameter
    m_nd = (
        ball.air_density * math.pi * diameter**5 * ball.c_m_alpha
        / (8.0 * ball.inertia_transverse)
    )
    if not m_nd:
        return math.inf
    p_nd = (ball.inertia_spin / ball.inertia_transverse) * spin * diameter / speed
    return p_nd**2 / (4.0 * m_nd)


def dynamic_stability(
    ball: BallPreset,
    speed: float,
    spin: float,
    model: AeroModel,
    speed_rate: float | None = None,
) -> DynamicStability:
    """
    Return the modes' per-second damping rates and McCoy's S_g, S_d.

    At air speed ``speed`` [m/s] and ``spin`` [rad/s], for the terms switched on in ``model``
    (the ball's air density); ``speed_rate`` [m/s^2] the air speed's change (None: drag alone,
    level flight; :func:`gravity_speed_rate` adds gravity's at a flight-path angle).

    The rates come from the time-domain linear equation with the WKB terms of the changing
    speed and spin: :func:`football_ros.physics.linear_theory.mode_rates` (docs/physics.md
    section 5), checked against rates measured in integrated flights; the flag
    ``dynamically_stable`` follows them. McCoy's factors are kept as reference numbers:
    S_g = P^2 / (4M), S_d = 2T/H with P = (I_s/I_t) p D / V, M = rho S D^3 C_Malpha / (2 I_t),
    H = rho S D / (2m) [C_Lalpha - C_D0 - (m D^2/I_t) C_Mq],
    T = rho S D / (2m) [C_Lalpha + (m D^2/I_s) C_Mpalpha] (the Magnus MOMENT). His H holds
    -C_D0 because, per calibre, P is assumed constant (spin falling with speed), while a
    football's spin barely changes: his criterion can call a ball whose both modes decay
    unstable (e.g. C_Mpalpha = 0.036).
    """
    mass, diameter, density = ball.mass, ball.diameter, ball.air_density
    inertia_spin, inertia_transverse = ball.inertia_spin, ball.inertia_transverse
    area = math.pi * diameter**2 / 4.0
    c_l = model.c_l_alpha if model.lift else 0.0
    c_d = model.c_d0 if model.drag else 0.0
    c_mpa = model.c_m_p_alpha if model.magnus else 0.0
    c_mq = model.c_m_q if model.pitch_damping else 0.0
    force_k = density * area * diameter / (2.0 * mass)
    t_nd = force_k * (c_l + mass * diameter**2 / inertia_spin * c_mpa)
    h_nd = force_k * (c_l - c_d - mass * diameter**2 / inertia_transverse * c_mq)
    s_g = gyroscopic_stability(ball, speed, spin)
    s_d = 2.0 * t_nd / h_nd if h_nd else math.nan
    mccoy = bool(s_g > 1.0 and np.isfinite(s_d) and 1.0 / s_g < s_d * (2.0 - s_d))
    params = dyn.make_params(ball, 'linear', model)
    fast, slow = mode_rates(params, speed, ball.inertia_ratio * spin, speed_rate)
    stable = bool(s_g > 1.0 and fast.real < 0.0 and slow.real < 0.0)
    return DynamicStability(
        s_g, s_d, stable, fast.real, slow.real, fast.imag, slow.imag, mccoy_stable=mccoy
    )


def gravity_speed_rate(
    ball: BallPreset, model: AeroModel, speed: float, flight_path_angle: float, gravity: float
) -> float:
    """
    Air speed's rate U' [m/s^2] with drag C_D0 and gravity at ``flight_path_angle`` [rad].

    U' = -rho S C_D0 U^2 / (2m) - g sin(Phi) (zero yaw, steady wind): a climbing ball slows.
    """
    c_d0 = model.c_d0 if model.drag else 0.0
    drag = ball.air_density * ball.reference_area * c_d0 / (2.0 * ball.mass) * speed**2
    return -drag - gravity * math.sin(flight_path_angle)


def modes_report(release: Release) -> dict:
    """
    Linear-theory numbers of a release as plain data (rad, rad/s, rpm, 1/s, m/s).

    The ball, settings, wind and modes :class:`football_ros.physics.flight.Flight` flies
    (:func:`flown_model`, :func:`flown_modes`), without importing the integrator (numba).
    Top level: the paper's frozen linear theory against the air; ``full`` (``--model full``):
    the full model's own local frequencies, damping rates and equilibrium at release; the
    damping rates in level flight (drag alone changes the speed) and ``*_gravity`` with the
    speed change of gravity at the release's flight-path angle; McCoy's factors as reference.
    """
    initial = release.initial_state()
    ball, aero, params = flown_model(
        release.preset(), release.model, release.moment, release.aero_model()
    )
    m = flown_modes(ball, initial, params)
    flown = aero or AeroModel().without_extras()
    gravity = float(params[dyn.P_GRAVITY])
    level = dynamic_stability(ball, m.speed, initial.spin, flown)
    climbing = dynamic_stability(
        ball,
        m.speed,
        initial.spin,
        flown,
        gravity_speed_rate(ball, flown, m.speed, m.flight_path_angle, gravity),
    )
    wind = params[dyn.P_WIND:dyn.P_WIND + 3]
    report = {
        'ball': release.ball,
        'model': release.model,
        'wind': [float(w) for w in wind],
        'ground_speed': float(np.linalg.norm(initial.velocity)),
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
        'dynamically_stable': level.dynamically_stable if release.model == 'full' else None,
        'fast_damping_rate': _finite_or_none(level.fast_damping_rate),
        'slow_damping_rate': _finite_or_none(level.slow_damping_rate),
        'fast_damping_rate_gravity': _finite_or_none(climbing.fast_damping_rate),
        'slow_damping_rate_gravity': _finite_or_none(climbing.slow_damping_rate),
        'dynamically_stable_gravity': climbing.dynamically_stable
        if release.model == 'full'
        else None,
        'dynamic_stability_factor': _finite_or_none(level.s_d),
        'mccoy_dynamically_stable': level.mccoy_stable if release.model == 'full' else None,
        'full': None,
    }
    if release.model == 'full':
        air = initial.velocity - wind
        x_p = complex(local_exponents(params, air, m.h1)[4])
        report['full'] = {
            'omega_fast': _finite_or_none(level.fast_frequency),
            'omega_slow': _finite_or_none(level.slow_frequency),
            'fast_damping_rate': _finite_or_none(level.fast_damping_rate),
            'slow_damping_rate': _finite_or_none(level.slow_damping_rate),
            'equilibrium_s2': x_p.real,
            'equilibrium_sideslip': x_p.imag,
            'equilibrium_alpha': float(angles_from_components(x_p)[0]),
            'equilibrium_beta': float(angles_from_components(x_p)[1]),
        }
    return report


def flight_warnings(
    release: Release,
    modes: LinearModes,
    times: np.ndarray,
    delta: np.ndarray,
    aero: AeroModel | None,
    ball: BallPreset,
) -> list[str]:
    """
    Sentences about a flight its user must know (``simulate`` prints them, plans carry them).

    A gyroscopically unstable release (``modes``: the flown modes), and the model forms whose
    data range the flight's total angle ``delta`` [rad] at ``times`` [s] left.
    """
    out = []
    if not modes.stable:
        out.append(
            f'the release is gyroscopically UNSTABLE: spin {release.spin_rpm:g} rpm is '
            f'below the critical {modes.critical_spin_rpm:.0f} rpm '
            f'(S_g = {modes.gyroscopic_stability_factor:.2f} < 1); the ball tumbles and '
            f'the linear theory does not apply'
        )
    if delta.size:
        worst = int(np.argmax(delta))
        texts = out_of_validity(float(delta[worst]), release.model, release.moment, aero, ball)
        for text in texts:
            out.append(f'{text}; largest at t = {times[worst]:.2f} s')
        limit = max_valid_delta(release.model, release.moment, aero)
        beyond = np.flatnonzero(delta > limit)
        if texts and beyond.size:
            out.append(
                f'the flight first leaves the data range ({math.degrees(limit):g} deg) '
                f'at t = {times[beyond[0]]:.2f} s'
            )
    return out


def _finite_or_none(value: float) -> float | None:
    return value + 0.0 if math.isfinite(value) else None  # + 0.0 turns -0.0 into 0.0
