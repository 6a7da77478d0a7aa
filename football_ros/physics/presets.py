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
Ball presets: the one place where ball and nominal-release numbers live.

Every number is SI (kg, m, kg m^2, kg/m^3, m/s, rad/s via rpm). Sources: Dzielski & Blackburn,
Dynamics 2022 (inertias, C_Malpha, nominal releases); diameter and air density chosen as
docs/physics.md section 4 states so that M_alpha = 191 s^-2 at 27.4 m/s for the American football.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math
from typing import Mapping


@dataclass(frozen=True)
class BallPreset:
    """
    Physical description of a ball and its nominal release.

    Attributes are SI: mass [kg], diameter and length [m], inertias [kg m^2] about the long
    (spin) axis and a transverse axis through the centre of mass, c_m_alpha [1/rad] is the
    overturning-moment slope, air_density [kg/m^3]. The nominal release: speed [m/s],
    elevation_deg [deg], spin_rpm [rev/min, sign = hand].
    """

    name: str
    mass: float
    diameter: float
    length: float
    inertia_spin: float
    inertia_transverse: float
    c_m_alpha: float
    air_density: float
    speed: float
    elevation_deg: float
    spin_rpm: float

    @property
    def reference_area(self) -> float:
        """Cross-section S = pi D^2 / 4 [m^2]."""
        return math.pi * self.diameter**2 / 4.0

    @property
    def inertia_ratio(self) -> float:
        """I_s / I_t (dimensionless)."""
        return self.inertia_spin / self.inertia_transverse

    def moment_coefficient(self) -> float:
        """K such that M_alpha(V) = k V^2 [1/m^2]: k = rho S D C_Malpha / (2 I_t)."""
        return (
            self.air_density
            * self.reference_area
            * self.diameter
            * self.c_m_alpha
            / (2.0 * self.inertia_transverse)
        )

    def with_overrides(self, overrides: Mapping[str, float]) -> 'BallPreset':
        """
        Return a copy with some numeric fields replaced, validated by :func:`check_ball`.

        Unknown keys, non-numbers, non-finite or non-positive values and values outside
        :data:`BALL_LIMITS` (or a combination :func:`check_ball` refuses) raise ValueError
        naming the parameter and its accepted range.
        """
        numeric = {f.name for f in dataclasses.fields(self)} - {
            'name',
            'speed',
            'elevation_deg',
            'spin_rpm',
        }
        changes = {}
        for key, value in overrides.items():
            if key not in numeric:
                raise ValueError(
                    f"unknown ball parameter '{str(key)[:40]}' "
                    f'(known: {", ".join(sorted(numeric))})'
                )
            number = _as_float(value)
            if number is None or not math.isfinite(number) or number <= 0.0:
                raise ValueError(
                    f"ball parameter '{key}' must be a positive finite number, "
                    f'got {str(value)[:40]!r}'
                )
            changes[key] = number
        ball = dataclasses.replace(self, **changes)
        check_ball(ball, changed=changes)
        return ball


def _as_float(value: object) -> float | None:
    """``value`` as a float if it is a real number (not a bool); integers too large -> inf."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        return float(value)
    except OverflowError:
        return math.inf


BALL_LIMITS: dict[str, tuple[float, float]] = {
    'mass': (0.05, 2.0),  # kg
    'diameter': (0.05, 0.4),  # m
    'length': (0.05, 0.6),  # m
    'inertia_spin': (1e-6, 0.1),  # kg m^2
    'inertia_transverse': (1e-6, 0.1),  # kg m^2
    'c_m_alpha': (0.01, 2.0),  # 1/rad
    'air_density': (0.3, 2.0),  # kg/m^3 (AeroModel accepts the same range)
}
"""Accepted ball parameters (SI). Every real ball is well inside, with margin for lab balls:

========================  ============  ============================================
parameter                 range         real balls
========================  ============  ============================================
mass [kg]                 0.05 - 2.0    NFL 0.40-0.43, youth 0.28-0.35, rugby 0.41-0.46,
                                        foam toys from about 0.1
diameter [m]              0.05 - 0.4    NFL 0.17, youth 0.15, rugby 0.18-0.19
length [m]                0.05 - 0.6    NFL 0.28, rugby 0.28-0.30
inertia_spin [kg m^2]     1e-6 - 0.1    NFL 0.0019, rugby 0.0026
inertia_transverse        1e-6 - 0.1    NFL 0.0032, rugby 0.0033
c_m_alpha [1/rad]         0.01 - 2.0    NFL 0.33 (0.165 sin 2 delta fit), rugby 0.147
air_density [kg/m^3]      0.3 - 2.0     0.74 at 5000 m to 1.5 at -40 C; sea level 1.225
========================  ============  ============================================

Combinations (:func:`check_ball`), true of every rigid body that fits in the ball:

- I_s <= 2 I_t: triangle inequality of the principal moments of an axisymmetric body
  (I_s = sum m (y^2 + z^2) <= sum m (x^2 + z^2) + sum m (x^2 + y^2) = 2 I_t);
- I_s / I_t >= 0.05 (:data:`MIN_INERTIA_RATIO`): a needle-like body below that, outside the
  model's use (the fastest nutation rate grows as I_t / I_s);
- I_s <= m (D/2)^2 and I_t <= m (max(L, D)/2)^2: no mass point of a body inside a spheroid of
  length L and diameter D is farther than D/2 from its long axis, or than max(L, D)/2 from a
  transverse axis through the centre.
"""

MIN_INERTIA_RATIO = 0.05


def check_ball(ball: 'BallPreset', changed: Mapping[str, float] | None = None) -> None:
    """
    Raise ValueError when ``ball`` is outside :data:`BALL_LIMITS` or its combinations.

    ``changed`` (the overridden keys) only orders the checks so that the message names the
    parameter the caller set.
    """
    order = list(changed or ()) + [k for k in BALL_LIMITS if k not in (changed or ())]
    for key in order:
        lo, hi = BALL_LIMITS[key]
        value = getattr(ball, key)
        if not lo <= value <= hi:
            raise ValueError(
                f"ball parameter '{key}' = {value:g} is outside the accepted range "
                f'[{lo:g}, {hi:g}]'
            )
    i_s, i_t, m = ball.inertia_spin, ball.inertia_transverse, ball.mass
    if i_s > 2.0 * i_t:
        raise ValueError(
            f"ball parameters 'inertia_spin' = {i_s:g} and 'inertia_transverse' = "
            f'{i_t:g}: a rigid body has inertia_spin <= 2 inertia_transverse'
        )
    if i_s < MIN_INERTIA_RATIO * i_t:
        raise ValueError(
            f"ball parameters 'inertia_spin' / 'inertia_transverse' = {i_s / i_t:g}"
            f' is below the accepted {MIN_INERTIA_RATIO:g}'
        )
    spin_max = m * (ball.diameter / 2.0) ** 2
    if i_s > spin_max:
        raise ValueError(
            f"ball parameter 'inertia_spin' = {i_s:g} exceeds mass (diameter/2)^2 "
            f'= {spin_max:g} kg m^2, the most a {m:g} kg ball of that diameter has'
        )
    transverse_max = m * (max(ball.length, ball.diameter) / 2.0) ** 2
    if i_t > transverse_max:
        raise ValueError(
            f"ball parameter 'inertia_transverse' = {i_t:g} exceeds mass "
            f'(max(length, diameter)/2)^2 = {transverse_max:g} kg m^2, the most a '
            f'{m:g} kg ball of that size has'
        )


PRESETS: dict[str, BallPreset] = {
    # American football, spiral pass (paper section 4). Mass: NFL ball, 14-15 oz -> 0.411 kg;
    # length 0.28 m (11 in) is used only for drawing.
    'american': BallPreset(
        name='american',
        mass=0.411,
        diameter=0.1726,
        length=0.28,
        inertia_spin=0.00194,
        inertia_transverse=0.00321,
        c_m_alpha=0.33,
        air_density=1.225,
        speed=27.4,
        elevation_deg=30.0,
        spin_rpm=600.0,
    ),
    # Rugby ball, screw kick (paper, from the rugby literature). Mass 0.43 kg (World Rugby:
    # 410-460 g), length 0.29 m for drawing.
    'rugby': BallPreset(
        name='rugby',
        mass=0.43,
        diameter=0.19,
        length=0.29,
        inertia_spin=0.0026,
        inertia_transverse=0.0033,
        c_m_alpha=0.147,
        air_density=1.225,
        speed=20.0,
        elevation_deg=30.0,
        spin_rpm=300.0,
    ),
}


AERO_SOURCES: dict[str, dict[str, str]] = {
    'american': {
        'c_m_alpha': 'Rae & Streit wind tunnel (via the paper): 0.33 /rad, C_M = 0.165 '
        'sin 2 delta to 50 deg',
        'c_d0, c_d2': 'ESTIMATE from Rae & Streit / Alam et al.: C_D 0.05-0.06 end-on to about '
        '0.35 broadside, delta 0-90 deg',
        'c_l_alpha': 'ESTIMATE: Rae & Streit lift ~ 0.2 sin 2 delta (wind axes), delta 0-50 deg',
        'c_m_q': 'ESTIMATE, no measurement (wobble decays over seconds), delta 0-20 deg',
        'c_l_p': 'ESTIMATE, no measurement (spin decays a few % per second)',
        'c_n_p_alpha, c_m_p_alpha': 'no data: 0',
    },
    'rugby': {
        'c_m_alpha': "ref. [15] of the paper (wind tunnel, normalised by the ball's volume, "
        'converted by the paper to the cross-section): 0.147 /rad',
        'c_d0, c_d2': "BORROWED from the American football's estimate (scaled by the rugby "
        "ball's own S and D). Published rugby-ball drag against yaw exists (Vance, Buick & "
        "Livesey, J. Appl. Mech. 79(2) 021020, 2012: 5-15 m/s; the paper's ref. [15]) but "
        'its tabulated values were not available to us',
        'c_l_alpha': "BORROWED from the American football's estimate. Vance et al. (2012) "
        'measured rugby-ball lift against yaw at 5-15 m/s, the best lift-to-drag ratio near '
        '40 deg yaw; their values were not available to us',
        'c_m_q': "BORROWED from the American football's estimate (no measurement for either)",
        'c_l_p': "BORROWED from the American football's estimate (no measurement for either)",
        'c_n_p_alpha, c_m_p_alpha': 'no data: 0',
    },
}
"""Where each aerodynamic number of a preset comes from (docs/physics.md, "Coefficients").

The full model's coefficients (:class:`football_ros.physics.aero.AeroModel`) are the same for
both balls; for the rugby ball only C_Malpha (and the inertias) are its own."""


def get_preset(name: str, overrides: Mapping[str, float] | None = None) -> BallPreset:
    """Look up a preset by name and apply overrides; unknown names raise ValueError."""
    try:
        preset = PRESETS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown ball preset '{name}' (known: {', '.join(PRESETS)})") from None
    return preset.with_overrides(overrides) if overrides else preset
