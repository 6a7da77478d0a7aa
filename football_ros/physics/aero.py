"""The "full" model: the paper's torque plus drag, lift, Magnus, damping and wind (physics.md s. 5).

Forms follow McCoy, *Modern Exterior Ballistics* (linearised projectile aerodynamics), with the
air-relative velocity u = v - wind, U = |u|, u_hat = u/U, axis s, delta = angle(u_hat, s),
p the spin [rad/s], w_perp the transverse angular velocity, q = 1/2 rho U^2 S (S = pi D^2/4):

    drag          F = -q (C_D0 + C_D2 sin^2 delta) u_hat
    lift/normal   F =  q C_Lalpha (s - cos(delta) u_hat)          (toward the nose, |.| = sin delta)
    Magnus force  F =  q (p D / U) C_Npalpha (u_hat x s)
    overturning   M =  q D C_Malpha f(delta) (u_hat x s)           (the paper's torque)
    pitch damping M =  q D (D / U) C_Mq w_perp                     (C_Mq < 0 damps)
    spin damping  M =  q D (D / U) C_lp p s                        (C_lp < 0: spin decays)
    Magnus moment M =  q D (p D / U) C_Mpalpha (u_hat - cos(delta) s)

Signs are this module's definitions (McCoy's conventions differ between editions); with every
coefficient zero and no wind the model is the paper's, to round-off.

Coefficients for the American football. Data are scarce (Dzielski & Blackburn, ASME Open J.
Eng. 2022, discuss which exist); every number below is labelled:
- C_D0 = 0.055, C_D2 = 0.30: ESTIMATE from Rae & Streit's wind-tunnel drag of a football, which
  rises from about 0.05-0.06 end-on to about 0.35 broadside (also Alam et al.).
- C_Lalpha = 0.40 /rad: ESTIMATE from Rae & Streit's normal force, C_L ~ 0.2 sin(2 delta).
- C_Malpha: the preset's (0.33 /rad, the paper; Rae & Streit's 0.165 sin 2 delta).
- C_Mq = -0.10: ESTIMATE (no football measurement known to us; chosen small so that the wobble
  decays over seconds, as films of spirals show).
- C_lp = -0.005: ESTIMATE (spin decays by a few percent per second).
- C_Npalpha = 0, C_Mpalpha = 0: no football data; set them to study Magnus effects.
The rugby preset uses the same estimates (no better data), scaled by its own S and D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any, Mapping

import numpy as np

from .presets import BallPreset

R_DRY_AIR = 287.05  # J/(kg K)


def air_density(altitude_m: float = 0.0, temperature_c: float = 15.0) -> float:
    """Dry-air density [kg/m^3]: ISA pressure at ``altitude_m`` and the given temperature."""
    pressure = 101325.0 * (1.0 - 2.25577e-5 * altitude_m) ** 5.25588
    return pressure / (R_DRY_AIR * (temperature_c + 273.15))


@dataclass(frozen=True)
class AeroModel:
    """Switches and coefficients of the full model (see the module docstring for sources).

    wind [m/s] in ``field``; air_density [kg/m^3] overrides the ball's if given, else
    altitude_m/temperature_c give it when either is set.
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

    LIMITS = {"c_d0": (0.0, 2.0), "c_d2": (0.0, 5.0), "c_l_alpha": (-5.0, 5.0), "c_n_p_alpha": (-5.0, 5.0),
              "c_m_q": (-100.0, 0.0), "c_l_p": (-1.0, 0.0), "c_m_p_alpha": (-5.0, 5.0),
              "air_density": (0.3, 2.0), "altitude_m": (-500.0, 6000.0), "temperature_c": (-40.0, 55.0),
              "wind": (-40.0, 40.0)}

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.type == "bool" or isinstance(value, bool):
                if not isinstance(value, bool):
                    raise ValueError(f"aero '{f.name}' must be true or false, got {value!r}")
                continue
            if f.name == "wind":
                if not isinstance(value, (list, tuple)) or len(value) != 3:
                    raise ValueError(f"aero 'wind' must be [x, y, z] in m/s, got {value!r}")
                object.__setattr__(self, "wind", tuple(_checked("wind", v, self.LIMITS["wind"]) for v in value))
            elif value is not None:
                object.__setattr__(self, f.name, _checked(f.name, value, self.LIMITS[f.name]))

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any] | None) -> "AeroModel":
        """Build from plain data; unknown keys raise ValueError."""
        data = dict(data or {})
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown aero key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
        return cls(**data)

    def to_mapping(self) -> dict[str, Any]:
        return {f.name: (list(getattr(self, f.name)) if f.name == "wind" else getattr(self, f.name))
                for f in fields(self)}

    def density(self, default: float) -> float:
        """Air density [kg/m^3] in force for this model."""
        if self.air_density is not None:
            return self.air_density
        if self.altitude_m is not None or self.temperature_c is not None:
            return air_density(self.altitude_m or 0.0, 15.0 if self.temperature_c is None else self.temperature_c)
        return default

    def without_extras(self) -> "AeroModel":
        """Every extra term off and no wind: the paper's model."""
        return replace(self, drag=False, lift=False, magnus=False, pitch_damping=False,
                       spin_damping=False, wind=(0.0, 0.0, 0.0))


def resolve(ball: BallPreset, model: str, aero: AeroModel | None) -> tuple[BallPreset, AeroModel | None]:
    """The ball and aero settings a ``model`` flies with: for ``full`` the given settings (or
    the defaults) and the ball with their air density; for ``paper`` the ball as it is and None."""
    if model != "full":
        return ball, None
    aero = aero or AeroModel()
    return ball.with_overrides({"air_density": aero.density(ball.air_density)}), aero


def _checked(name: str, value: Any, limits: tuple[float, float]) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"aero '{name}' must be a finite number, got {value!r}")
    lo, hi = limits
    if not lo <= value <= hi:
        raise ValueError(f"aero '{name}' = {value:g} is outside [{lo:g}, {hi:g}]")
    return float(value)


@dataclass(frozen=True)
class DynamicStability:
    """McCoy's linearised stability numbers (per calibre travelled, made per second with V/D).

    s_g: gyroscopic stability factor P^2/(4M); s_d: dynamic stability factor 2T/H;
    dynamically_stable: 1/S_g < S_d (2 - S_d); fast/slow_damping_rate [1/s]: the modes'
    exponential rates lambda V / D (negative = the mode decays).
    """

    s_g: float
    s_d: float
    dynamically_stable: bool
    fast_damping_rate: float
    slow_damping_rate: float


def dynamic_stability(ball: BallPreset, speed: float, spin: float, model: AeroModel) -> DynamicStability:
    """McCoy's P, M, T, H and the mode damping rates at ``speed`` [m/s] and ``spin`` [rad/s], for
    the terms switched on in ``model`` (the ball's air density)."""
    mass, diameter, density, c_m_alpha = ball.mass, ball.diameter, ball.air_density, ball.c_m_alpha
    inertia_spin, inertia_transverse = ball.inertia_spin, ball.inertia_transverse
    area = math.pi * diameter ** 2 / 4.0
    p_nd = (inertia_spin / inertia_transverse) * spin * diameter / speed
    m_nd = density * area * diameter ** 3 / (2.0 * inertia_transverse) * c_m_alpha
    c_l = model.c_l_alpha if model.lift else 0.0
    c_d = model.c_d0 if model.drag else 0.0
    c_np = model.c_n_p_alpha if model.magnus else 0.0
    c_mq = model.c_m_q if model.pitch_damping else 0.0
    t_nd = density * area * diameter / (2.0 * mass) * (c_l + mass * diameter ** 2 / inertia_spin * c_np)
    h_nd = density * area * diameter / (2.0 * mass) * (c_l - c_d - mass * diameter ** 2 / inertia_transverse * c_mq)
    s_g = p_nd ** 2 / (4.0 * m_nd) if m_nd else math.inf
    s_d = 2.0 * t_nd / h_nd if h_nd else math.nan
    root = math.sqrt(p_nd ** 2 - 4.0 * m_nd) if p_nd ** 2 > 4.0 * m_nd else math.nan
    lam_f = -0.5 * (h_nd - p_nd * (2.0 * t_nd - h_nd) / root)
    lam_s = -0.5 * (h_nd + p_nd * (2.0 * t_nd - h_nd) / root)
    stable = bool(s_g > 1.0 and np.isfinite(s_d) and 1.0 / s_g < s_d * (2.0 - s_d))
    return DynamicStability(s_g, s_d, stable, lam_f * speed / diameter, lam_s * speed / diameter)
