"""Linear theory in the velocity frame: frozen at release, and quasi-steady along the flight.

With x = s2 + i s3 (velocity-frame components of the axis, against the air-relative velocity
u = v - wind) and h1 = h.s (docs/physics.md, "Linear theory"):

    x'' - i h1 x' - M_alpha x = i w_V h1,   w_V = -g cos(Phi) / U

Frozen (the paper): U and Phi held at their release values, solved in closed form,
x(t) = C1 exp(i w_f t) + C2 exp(i w_s t) + i s3p.

Quasi-steady (the paper's remark that the solution "can be applied at any point along the
trajectory", made into a solution): the local M_alpha(U(t)), h1(t), w_f(t), w_s(t) and s3p(t)
along the flight, the phases integrated, x(t) = A(t) [C1 exp(i int w_f) + C2 exp(i int w_s)]
+ i s3p(t), with the adiabatic (first-order WKB) amplitude A = sqrt(D(0) / D(t)),
D = sqrt(h1^2 - 4 M_alpha), the same for both modes.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np

from . import frames
from .presets import BallPreset
from .release import RPM, InitialState


def angles_from_components(x) -> tuple[np.ndarray, np.ndarray]:
    """alpha, beta [rad] of the unit axis with velocity-frame components
    (sqrt(1 - s2^2 - s3^2), s2, s3), x = s2 + i s3 (complex, any shape)."""
    x = np.asarray(x)
    s2, s3 = np.clip(x.real, -1.0, 1.0), np.clip(x.imag, -1.0, 1.0)
    s1 = np.sqrt(np.clip(1.0 - s2 ** 2 - s3 ** 2, 0.0, None))
    return np.arctan2(s2, s1), np.arcsin(s3)


@dataclass(frozen=True)
class LinearModes:
    """Linear-theory numbers of one release. Rates in rad/s, angles in rad.

    m_alpha [1/s^2], h1 [rad/s], omega_fast/omega_slow: real parts of the mode frequencies
    (for an unstable ball the modes are complex and ``growth_rate`` [1/s] is the e-folding rate
    of the growing one), equilibrium_sideslip s3p [rad] (positive = nose right), c1, c2:
    complex mode amplitudes [rad], omega_v: turn rate of the velocity frame [rad/s]; speed [m/s]
    and flight_path_angle [rad] of the air-relative velocity at release.
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
        return angles_from_components(self.axis_components(t))


def moment_slope(ball: BallPreset, speed: float) -> float:
    """M_alpha(V) = rho S D V^2 C_Malpha / (2 I_t) [1/s^2]."""
    return ball.moment_coefficient() * speed ** 2


def linear_modes(ball: BallPreset, state: InitialState, gravity: float = frames.GRAVITY,
                 wind=None) -> LinearModes:
    """Modes, equilibrium and mode amplitudes for a release, U and Phi frozen at release.

    ``wind`` [m/s] in ``field``: the theory uses the air-relative velocity u = v - wind.
    """
    air = frames.air_velocity(state.velocity, wind)
    speed = float(np.linalg.norm(air))
    phi = float(frames.flight_path_angle(air))
    m_alpha = moment_slope(ball, speed)
    h1 = ball.inertia_ratio * state.spin
    disc = cmath.sqrt(h1 ** 2 - 4.0 * m_alpha)
    w_f, w_s = (h1 + disc) / 2.0, (h1 - disc) / 2.0
    omega_v = -gravity * math.cos(phi) / speed
    s3p = gravity * math.cos(phi) * h1 / (m_alpha * speed)
    # Initial axis and its rate seen in the velocity frame (which turns at omega_v about e3).
    e1, e2, e3 = frames.velocity_frame(air)
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


def local_modes(moment_k: float, air_velocity: np.ndarray, h1, gravity: float = frames.GRAVITY):
    """Local linear-theory numbers along a flight (arrays broadcast over samples).

    ``moment_k`` = M_alpha / U^2 [1/m^2], ``air_velocity`` (..., 3) [m/s], ``h1`` [rad/s].
    Returns (w_f, w_s, D, s3p): complex mode frequencies [rad/s], D = sqrt(h1^2 - 4 M_alpha)
    (complex), and the local equilibrium sideslip s3p [rad].
    """
    air = np.asarray(air_velocity, dtype=float)
    speed = np.linalg.norm(air, axis=-1)
    phi = frames.flight_path_angle(air)
    m_alpha = moment_k * speed ** 2
    h1 = np.asarray(h1, dtype=float)
    disc = np.sqrt((h1 ** 2 - 4.0 * m_alpha).astype(complex))
    s3p = gravity * np.cos(phi) * h1 / (m_alpha * speed)
    return (h1 + disc) / 2.0, (h1 - disc) / 2.0, disc, s3p


def quasi_steady_components(modes: LinearModes, moment_k: float, times: np.ndarray,
                            air_velocities: np.ndarray, h1, gravity: float = frames.GRAVITY) -> np.ndarray:
    """x(t) = s2 + i s3 of the quasi-steady linear theory at ``times`` [s] (increasing, the
    first one the release), from the flight's air-relative velocities (N, 3) [m/s] and h1.

    Phases: trapezoidal integrals of the local w_f, w_s over the samples (error ~ dt^2 w'').
    """
    times = np.asarray(times, dtype=float)
    w_f, w_s, disc, s3p = local_modes(moment_k, air_velocities, np.broadcast_to(h1, times.shape), gravity)
    dt = np.diff(times)
    theta_f = np.concatenate([[0.0], np.cumsum(0.5 * dt * (w_f[1:] + w_f[:-1]))])
    theta_s = np.concatenate([[0.0], np.cumsum(0.5 * dt * (w_s[1:] + w_s[:-1]))])
    amp = np.sqrt(disc[0] / disc)
    return amp * (modes.c1 * np.exp(1j * theta_f) + modes.c2 * np.exp(1j * theta_s)) + 1j * s3p


class QuasiSteadyTracker:
    """The quasi-steady linear theory sample by sample (real time): call :meth:`update` with
    non-decreasing times; phases are integrated by the trapezoid rule between calls."""

    def __init__(self, modes: LinearModes, moment_k: float, gravity: float = frames.GRAVITY) -> None:
        self.modes, self.moment_k, self.gravity = modes, moment_k, gravity
        self._t = 0.0  # the release
        self._w = modes._roots()
        self._theta = [0j, 0j]
        self._disc0 = cmath.sqrt(modes.h1 ** 2 - 4.0 * modes.m_alpha)

    def update(self, t: float, air_velocity: np.ndarray, h1: float) -> np.ndarray:
        """alpha, beta [rad] of the quasi-steady theory at ``t`` [s] since release."""
        w_f, w_s, disc, s3p = (complex(x) for x in local_modes(self.moment_k, air_velocity, h1, self.gravity))
        if t > self._t:
            dt = t - self._t
            self._theta[0] += 0.5 * dt * (w_f + self._w[0])
            self._theta[1] += 0.5 * dt * (w_s + self._w[1])
            self._t, self._w = t, (w_f, w_s)
        amp = cmath.sqrt(self._disc0 / disc) if disc != 0 else math.inf
        x = (amp * (self.modes.c1 * cmath.exp(1j * self._theta[0])
                    + self.modes.c2 * cmath.exp(1j * self._theta[1])) + 1j * s3p.real)
        alpha, beta = angles_from_components(x)
        return np.array([float(alpha), float(beta)])
