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
        Return a copy with some numeric fields replaced.

        Unknown or non-positive values raise ValueError.
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
                    f"unknown ball parameter '{key}' (known: {', '.join(sorted(numeric))})"
                )
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not math.isfinite(value)
                or value <= 0.0
            ):
                raise ValueError(
                    f"ball parameter '{key}' must be a positive finite number, "
                    f'got {str(value)[:40]!r}'
                )
            changes[key] = float(value)
        return dataclasses.replace(self, **changes)


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


def get_preset(name: str, overrides: Mapping[str, float] | None = None) -> BallPreset:
    """Look up a preset by name and apply overrides; unknown names raise ValueError."""
    try:
        preset = PRESETS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown ball preset '{name}' (known: {', '.join(PRESETS)})") from None
    return preset.with_overrides(overrides) if overrides else preset
