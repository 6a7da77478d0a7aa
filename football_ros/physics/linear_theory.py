"""Linear theory in the velocity frame, V and Phi frozen (physics.md section 3).

With x = s2 + i s3 (velocity-frame components of the axis) and h1 = h.s:

    x'' - i h1 x' - M_alpha x = i w_V h1,   w_V = -g cos(Phi) / V

solved in closed form: x(t) = C1 exp(i w_f t) + C2 exp(i w_s t) + i s3p.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from . import frames
from .presets import BallPreset
from .release import RPM, InitialState


@dataclass(frozen=True)
class LinearModes:
    """Linear-theory numbers of one release. Rates in rad/s, angles in rad.

    m_alpha [1/s^2], h1 [rad/s], omega_fast/omega_slow: real parts of the mode frequencies
    (for an unstable ball the modes are complex and ``growth_rate`` [1/s] is the e-folding rate
    of the growing one), equilibrium_sideslip s3p [rad] (positive = nose right), c1, c2:
    complex mode amplitudes [rad], omega_v: turn rate of the velocity frame [rad/s].
    """

    m_alpha: float
    h1: float
    omega_fast: float
    omega_slow: float
    growth_rate: float
    stable: bool
    critical_spin_rpm: float
    equilibrium_sideslip: float
    c1: complex
    c2: complex
    omega_v: float
    speed: float
    flight_path_angle: float

    @property
    def gyroscopic_stability_factor(self) -> float:
        """S_g = h1^2 / (4 M_alpha) (McCoy's P^2 / 4M); > 1 means gyroscopically stable."""
        return self.h1 ** 2 / (4.0 * self.m_alpha)

    def _roots(self) -> tuple[complex, complex]:
        disc = cmath.sqrt(self.h1 ** 2 - 4.0 * self.m_alpha)
        return (self.h1 + disc) / 2.0, (self.h1 - disc) / 2.0

    def axis_components(self, t: np.ndarray) -> np.ndarray:
        """x(t) = s2 + i s3 at times ``t`` [s] after release (complex array)."""
        w_f, w_s = self._roots()
        t = np.asarray(t, dtype=float)
        return (self.c1 * np.exp(1j * w_f * t) + self.c2 * np.exp(1j * w_s * t)
                + 1j * self.equilibrium_sideslip)

    def aero_angles(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Predicted alpha, beta [rad] at times ``t``: the angles of the unit axis with
        velocity-frame components (sqrt(1 - s2^2 - s3^2), s2, s3)."""
        x = self.axis_components(t)
        s2, s3 = x.real, np.clip(x.imag, -1.0, 1.0)
        s1 = np.sqrt(np.clip(1.0 - s2 ** 2 - s3 ** 2, 0.0, None))
        return np.arctan2(s2, s1), np.arcsin(s3)


def moment_slope(ball: BallPreset, speed: float) -> float:
    """M_alpha(V) = rho S D V^2 C_Malpha / (2 I_t) [1/s^2]."""
    return ball.moment_coefficient() * speed ** 2


def linear_modes(ball: BallPreset, state: InitialState, gravity: float = frames.GRAVITY) -> LinearModes:
    """Modes, equilibrium and mode amplitudes for a release, V and Phi frozen at release."""
    speed = float(np.linalg.norm(state.velocity))
    phi = float(frames.flight_path_angle(state.velocity))
    m_alpha = moment_slope(ball, speed)
    h1 = ball.inertia_ratio * state.spin
    disc = cmath.sqrt(h1 ** 2 - 4.0 * m_alpha)
    w_f, w_s = (h1 + disc) / 2.0, (h1 - disc) / 2.0
    omega_v = -gravity * math.cos(phi) / speed
    s3p = gravity * math.cos(phi) * h1 / (m_alpha * speed)
    # Initial axis and its rate seen in the velocity frame (which turns at omega_v about e3).
    e1, e2, e3 = frames.velocity_frame(state.velocity)
    axis_rate = np.cross(state.transverse_rate, state.axis)
    rate_rel = axis_rate - omega_v * np.cross(e3, state.axis)
    s2, s3 = float(state.axis @ e2), float(state.axis @ e3)
    s2_dot, s3_dot = float(rate_rel @ e2), float(rate_rel @ e3)
    x0 = complex(s2, s3)
    rate = complex(s3_dot, -s2_dot)
    offset = x0 - 1j * s3p
    c1 = (rate - w_s * offset) / (w_f - w_s)
    c2 = (-rate + w_f * offset) / (w_f - w_s)
    return LinearModes(
        m_alpha=m_alpha, h1=h1, omega_fast=w_f.real, omega_slow=w_s.real,
        growth_rate=abs(disc.imag) / 2.0, stable=h1 ** 2 > 4.0 * m_alpha,
        critical_spin_rpm=2.0 * math.sqrt(m_alpha) / ball.inertia_ratio / RPM,
        equilibrium_sideslip=s3p, c1=complex(c1), c2=complex(c2), omega_v=omega_v,
        speed=speed, flight_path_angle=phi)
