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
The "full" model: the paper's torque plus drag, lift, Magnus, damping, wind (docs/physics.md).

Forms follow McCoy, *Modern Exterior Ballistics* (linearised projectile aerodynamics), with the
air-relative velocity u = v - wind, U = |u|, u_hat = u/U, axis s, delta = angle(u_hat, s),
p the spin [rad/s], w_perp the transverse angular velocity, q = 1/2 rho U^2 S (S = pi D^2/4):

    drag          F = -q (C_D0 + C_D2 sin^2 delta) u_hat
    lift          F =  q C_Lalpha cos(delta) (s - cos(delta) u_hat)  (|.| = C_Lalpha/2 sin 2 delta)
    Magnus force  F =  q (p D / U) C_Npalpha (s x u_hat)             (classical: along p s x u)
    overturning   M =  q D C_Malpha f(delta) (u_hat x s)           (the paper's torque)
    pitch damping M =  q D (D / U) C_Mq w_perp                     (C_Mq < 0 damps)
    spin damping  M =  q D (D / U) C_lp p s                        (C_lp < 0: spin decays)
    Magnus moment M =  q D (p D / U) C_Mpalpha (u_hat - cos(delta) s)

Signs: a positive C_Npalpha gives the classical Magnus direction p s x u (with p > 0 and the
nose right of u, an upward force); a positive C_Mpalpha enters McCoy's lift-like factor
T = rho S D / (2m) [C_Lalpha + (m D^2 / I_s) C_Mpalpha] with a plus sign (so both match McCoy's
linear theory, derived in docs/physics.md). These signs are this package's convention:
a tabulated C_Npalpha or C_Mpalpha from a source with another convention may need its sign
flipped (docs/physics.md, "Signs"). With every coefficient zero and no wind the model is
the paper's, to round-off.

Coefficients for the American football. Data are scarce (Dzielski & Blackburn, ASME Open J.
Eng. 2022, discuss which exist); every number is labelled and :data:`VALIDITY` gives the
range of total angle delta each form covers:
- C_D0 = 0.055, C_D2 = 0.30: ESTIMATE from Rae & Streit's wind-tunnel drag of a football, which
  rises from about 0.05-0.06 end-on to about 0.35 broadside (also Alam et al.); the sin^2 form
  joins the two ends, delta 0-90 deg (McCoy's C_D0 + C_Ddelta2 delta^2 at small delta).
- C_Lalpha = 0.40 /rad: ESTIMATE, C_L = 0.2 sin(2 delta), applied as LIFT (perpendicular to
  u). The secondary sources that use Rae & Streit's data (Rae 2003; Dzielski & Blackburn,
  ASME 2022; the project's physics reference) call them drag, lift and moment (C_D, C_L,
  C_M), i.e. wind axes, not normal and axial force; the original table was not available to
  us. The sin 2 delta shape covers delta 0-50 deg. Were it a normal-force fit, the lift would
  be C_N cos(delta) - C_X sin(delta) (slope about 0.345; at 30 deg the lift here would be
  about 40 % too high):
  docs/physics.md, "Lift or normal force".
- C_Malpha: the preset's (0.33 /rad, the paper); ``sin2delta`` uses Rae & Streit's curve
  0.165 sin 2 delta (valid to 50 deg). The ``linear`` torque is C_Malpha sin(delta) (a cross
  product), 1/cos(delta) times Rae & Streit's: 10 % above it at acos(1/1.1) = 24.6 deg.
- C_Mq = -0.10: ESTIMATE (no football measurement known to us; chosen small so that the wobble
  decays over seconds, as films of spirals show). Small-angle linear form, 0-20 deg.
- C_lp = -0.005: ESTIMATE (spin decays by a few percent per second). Any delta.
- C_Npalpha = 0, C_Mpalpha = 0: no football data; set them to study Magnus effects (McCoy's
  small-angle forms, 0-20 deg).
The rugby preset's C_Malpha is its own (the paper's ref. [15]); its drag, lift and damping
numbers are still BORROWED from the American football above, scaled by its own S and D:
published rugby-ball lift and drag against yaw (Vance, Buick & Livesey, J. Appl. Mech. 79(2)
021020, 2012, at 5-15 m/s) were not available to us as numbers.
:data:`football_ros.physics.presets.AERO_SOURCES` lists each number's source per ball.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
import math
from typing import Any, Mapping

from .presets import BallPreset

R_DRY_AIR = 287.05  # J/(kg K)


ISA_LAPSE = 0.0065  # K/m, ISA troposphere temperature lapse rate


def isa_temperature_c(altitude_m: float) -> float:
    """ISA temperature [deg C] at ``altitude_m`` [m]: 15 C at sea level, -6.5 K per km."""
    return 15.0 - ISA_LAPSE * altitude_m


def air_density(altitude_m: float = 0.0, temperature_c: float | None = None) -> float:
    """
    Dry-air density [kg/m^3].

    ISA pressure at ``altitude_m`` [m] and ``temperature_c`` [deg C], or the ISA temperature
    there when None (the ISA density: 1.0467 at 1609 m).
    """
    pressure = 101325.0 * (1.0 - 2.25577e-5 * altitude_m) ** 5.25588
    if temperature_c is None:
        temperature_c = isa_temperature_c(altitude_m)
    return pressure / (R_DRY_AIR * (temperature_c + 273.15))


@dataclass(frozen=True)
class AeroModel:
    """
    Switches and coefficients of the full model (see the module docstring for sources).

    wind [m/s] in ``field``; air_density [kg/m^3] overrides the ball's if given, else
    altitude_m/temperature_c give it when either is set (a missing temperature is the ISA
    temperature at the altitude, a missing altitude is sea level).
    """

    drag: bool = True
    lift: bool = True
    magnus: bool = True
    pitch_damping: bool = True
    spin_damping: bool = True
    c_d0: float = 0.055
    c_d2: float = 0.30
    c_l_alpha: float = 0.40
    c_n_p_alpha: float = 0.0
    c_m_q: float = -0.10
    c_l_p: float = -0.005
    c_m_p_alpha: float = 0.0
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)
    air_density: float | None = None
    altitude_m: float | None = None
    temperature_c: float | None = None

    LIMITS = {
        'c_d0': (0.0, 2.0),
        'c_d2': (0.0, 5.0),
        'c_l_alpha': (-5.0, 5.0),
        'c_n_p_alpha': (-5.0, 5.0),
        'c_m_q': (-100.0, 0.0),
        'c_l_p': (-1.0, 0.0),
        'c_m_p_alpha': (-5.0, 5.0),
        'air_density': (0.3, 2.0),
        'altitude_m': (-500.0, 6000.0),
        'temperature_c': (-40.0, 55.0),
        'wind': (-40.0, 40.0),
    }

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.type == 'bool' or isinstance(value, bool):
                if not isinstance(value, bool):
                    raise ValueError(f"aero '{f.name}' must be true or false, got {value!r}")
                continue
            if f.name == 'wind':
                if not isinstance(value, (list, tuple)) or len(value) != 3:
                    raise ValueError(f"aero 'wind' must be [x, y, z] in m/s, got {value!r}")
                object.__setattr__(
                    self, 'wind', tuple(_checked('wind', v, self.LIMITS['wind']) for v in value)
                )
            elif value is not None:
                object.__setattr__(self, f.name, _checked(f.name, value, self.LIMITS[f.name]))
        if self.air_density is not None and (
            self.altitude_m is not None or self.temperature_c is not None
        ):
            raise ValueError(
                "aero 'air_density' conflicts with 'altitude_m'/'temperature_c' (they give the"
                ' density): set one or the other'
            )

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any] | None) -> 'AeroModel':
        """Build from plain data; unknown keys raise ValueError."""
        data = dict(data or {})
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f'unknown aero key(s) {", ".join(unknown)}; known: {", ".join(sorted(known))}'
            )
        return cls(**data)

    def to_mapping(self) -> dict[str, Any]:
        return {
            f.name: (list(getattr(self, f.name)) if f.name == 'wind' else getattr(self, f.name))
            for f in fields(self)
        }

    def density(self, default: float) -> float:
        """Air density [kg/m^3] in force for this model."""
        if self.air_density is not None:
            return self.air_density
        if self.altitude_m is not None or self.temperature_c is not None:
            return air_density(self.altitude_m or 0.0, self.temperature_c)
        return default

    def without_extras(self) -> 'AeroModel':
        """Every extra term off and no wind: the paper's model."""
        return replace(
            self,
            drag=False,
            lift=False,
            magnus=False,
            pitch_damping=False,
            spin_damping=False,
            wind=(0.0, 0.0, 0.0),
        )


def resolve(
    ball: BallPreset, model: str, aero: AeroModel | None
) -> tuple[BallPreset, AeroModel | None]:
    """
    Return the ball and aero settings a ``model`` flies with.

    For ``full`` the given settings (or the defaults) and the ball with their air density; for
    ``paper`` the ball as it is and None.
    """
    if model != 'full':
        return ball, None
    aero = aero or AeroModel()
    return ball.with_overrides({'air_density': aero.density(ball.air_density)}), aero


def _checked(name: str, value: Any, limits: tuple[float, float]) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"aero '{name}' must be a finite number, got {value!r}")
    lo, hi = limits
    if not lo <= value <= hi:
        raise ValueError(f"aero '{name}' = {value:g} is outside [{lo:g}, {hi:g}]")
    return float(value)


@dataclass(frozen=True)
class ValidityRange:
    """The range of total angle delta [deg] over which a form follows its data, and the source."""

    term: str
    max_delta_deg: float
    source: str


VALIDITY: dict[str, ValidityRange] = {
    'moment_linear': ValidityRange(
        'overturning moment, linear slope C_Malpha sin delta',
        24.6,
        "the paper's linear slope; at most 10 % above Rae & Streit's form C_Malpha/2 sin 2 "
        'delta (ratio 1/cos delta) up to 24.6 deg',
    ),
    'moment_sin2delta': ValidityRange(
        "overturning moment, Rae & Streit's form C_M = C_Malpha/2 sin 2 delta",
        50.0,
        'Rae & Streit wind-tunnel fit, 0-50 deg',
    ),
    'lift': ValidityRange(
        'lift C_Lalpha/2 sin 2 delta',
        50.0,
        'Rae & Streit lift (wind axes) ~ sin 2 delta, 0-50 deg (C_Lalpha ESTIMATE)',
    ),
    'drag': ValidityRange(
        'drag C_D0 + C_D2 sin^2 delta',
        90.0,
        'Rae & Streit / Alam et al.: end-on to broadside (ESTIMATE)',
    ),
    'magnus': ValidityRange(
        'Magnus force and moment (McCoy small-angle forms)',
        20.0,
        'McCoy linear forms, no football data',
    ),
    'pitch_damping': ValidityRange(
        'pitch damping C_Mq (McCoy small-angle form)',
        20.0,
        'McCoy linear form, ESTIMATE, no football data',
    ),
}
"""Validity of each form in total angle delta (docs/physics.md, 'Validity ranges')."""


def validity_terms(model: str, moment: str, aero: AeroModel | None) -> list[str]:
    """Keys of :data:`VALIDITY` whose forms act in a flight of ``model``/``moment``/``aero``."""
    terms = ['moment_sin2delta' if moment == 'sin2delta' else 'moment_linear']
    if model != 'full' or aero is None:
        return terms
    if aero.lift and aero.c_l_alpha:
        terms.append('lift')
    if aero.drag and (aero.c_d0 or aero.c_d2):
        terms.append('drag')
    if aero.magnus and (aero.c_n_p_alpha or aero.c_m_p_alpha):
        terms.append('magnus')
    if aero.pitch_damping and aero.c_m_q:
        terms.append('pitch_damping')
    return terms


def max_valid_delta(
    model: str = 'paper', moment: str = 'linear', aero: AeroModel | None = None
) -> float:
    """
    Return the largest total angle delta [rad] inside every form in force.

    A cheap per-sample test (``delta > max_valid_delta(...)``) before :func:`out_of_validity`
    words the warning.
    """
    terms = validity_terms(model, moment, aero)
    return math.radians(min(VALIDITY[k].max_delta_deg for k in terms))


def out_of_validity(
    delta: float,
    model: str = 'paper',
    moment: str = 'linear',
    aero: AeroModel | None = None,
    ball: BallPreset | None = None,
) -> list[str]:
    """
    Pure check of one state (or a flight's largest angle).

    The forms in force whose data range the total angle ``delta`` [rad] exceeds, one sentence
    each (empty: all within); with ``ball``, the moment forms carry its own C_Malpha (e.g.
    0.165 sin 2 delta for the American football, 0.0735 for the rugby ball).

    For the simulator's /diagnostics (WARN with these sentences) and ``simulate`` (stderr).
    """
    if not math.isfinite(delta):
        return ['total angle delta is not finite']
    deg = math.degrees(abs(delta))
    out = []
    for key in validity_terms(model, moment, aero):
        rng = VALIDITY[key]
        if deg > rng.max_delta_deg:
            text = (
                f'delta = {deg:.1f} deg is beyond the {rng.max_delta_deg:g} deg range of '
                f'the {rng.term} ({rng.source})'
            )
            if ball is not None and key.startswith('moment'):
                text = text.replace('C_Malpha/2', f'{ball.c_m_alpha / 2:.4g}').replace(
                    'C_Malpha sin', f'{ball.c_m_alpha:.4g} sin'
                )
            out.append(text)
    return out
