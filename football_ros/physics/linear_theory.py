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
Linear theory in the velocity frame: frozen at release, and quasi-steady along the flight.

With x = s2 + i s3 (velocity-frame components of the axis, against the air-relative velocity
u = v - wind) and h1 = h.s (docs/physics.md, "Linear theory"):

    x'' - i h1 x' - M_alpha x = i w_V h1,   w_V = -g cos(Phi) / U

Frozen (the paper): U and Phi held at their release values, solved in closed form,
x(t) = C1 exp(i w_f t) + C2 exp(i w_s t) + i s3p.

Quasi-steady (the paper's remark that the solution "can be applied at any point along the
trajectory", made into a solution): the local M_alpha(U(t)), h1(t), mode exponents and
equilibrium along the flight, the phases integrated, with the first-order WKB amplitudes and
the equilibrium's first-order drift. For the paper's model
x(t) = A(t) [K1 exp(i int w_f) + K2 exp(i int w_s)] + i s3p(t) + h1 s3p'(t) / M_alpha(t),
A = sqrt(D(0) / D(t)), D = sqrt(h1^2 - 4 M_alpha); for the full model the exponents and
equilibrium of its own linear equation (lift, damping, Magnus; :func:`local_exponents`).
"""

from __future__ import annotations

import cmath
from dataclasses import dataclass
import math

import numpy as np

from . import frames
from . import model_params as dyn
from .presets import BallPreset
from .release import InitialState, RPM


def angles_from_components(x) -> tuple[np.ndarray, np.ndarray]:
    """
    Return alpha, beta [rad] of the unit axis from x = s2 + i s3.

    Velocity-frame components (sqrt(1 - s2^2 - s3^2), s2, s3), x = s2 + i s3 (complex, any
    shape).
    """
    x = np.asarray(x)
    s2, s3 = np.clip(x.real, -1.0, 1.0), np.clip(x.imag, -1.0, 1.0)
    s1 = np.sqrt(np.clip(1.0 - s2**2 - s3**2, 0.0, None))
    return np.arctan2(s2, s1), np.arcsin(s3)


@dataclass(frozen=True)
class LinearModes:
    """
    Linear-theory numbers of one release. Rates in rad/s, angles in rad.

    m_alpha [1/s^2], h1 [rad/s], omega_fast/omega_slow: real parts of the mode frequencies,
    fast = the larger |omega|; both have the sign of h1 (negative for a left-handed spiral,
    p < 0), and c1 is the fast mode's amplitude whatever the sign
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
        return self.h1**2 / (4.0 * self.m_alpha)

    def _roots(self) -> tuple[complex, complex]:
        return mode_frequencies(self.h1, self.m_alpha)

    def axis_components(self, t: np.ndarray) -> np.ndarray:
        """x(t) = s2 + i s3 at times ``t`` [s] after release (complex array)."""
        w_f, w_s = self._roots()
        t = np.asarray(t, dtype=float)
        return (
            self.c1 * np.exp(1j * w_f * t)
            + self.c2 * np.exp(1j * w_s * t)
            + 1j * self.equilibrium_sideslip
        )

    def aero_angles(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Predicted alpha, beta [rad] at times ``t``.

        The angles of the unit axis with velocity-frame components (sqrt(1 - s2^2 - s3^2),
        s2, s3).
        """
        return angles_from_components(self.axis_components(t))


def mode_frequencies(h1: float, m_alpha: float) -> tuple[complex, complex]:
    """
    (w_fast, w_slow) [rad/s], the roots of w^2 - h1 w + M_alpha = 0, fast = larger |w|.

    w = (h1 +- sign(h1) sqrt(h1^2 - 4 M_alpha)) / 2: both carry the sign of h1 (a left-handed
    spiral's modes turn the other way, w(-h1) = -w(h1)); complex when gyroscopically unstable.
    """
    disc = cmath.sqrt(h1**2 - 4.0 * m_alpha)
    if h1 < 0.0:
        disc = -disc
    return (h1 + disc) / 2.0, (h1 - disc) / 2.0


def moment_slope(ball: BallPreset, speed: float) -> float:
    """M_alpha(V) = rho S D V^2 C_Malpha / (2 I_t) [1/s^2]."""
    return ball.moment_coefficient() * speed**2


def linear_modes(
    ball: BallPreset, state: InitialState, gravity: float = frames.GRAVITY, wind=None
) -> LinearModes:
    """
    Modes, equilibrium and mode amplitudes for a release, U and Phi frozen at release.

    ``wind`` [m/s] in ``field``: the theory uses the air-relative velocity u = v - wind.
    """
    air = frames.air_velocity(state.velocity, wind)
    speed = float(np.linalg.norm(air))
    phi = float(frames.flight_path_angle(air))
    m_alpha = moment_slope(ball, speed)
    h1 = ball.inertia_ratio * state.spin
    w_f, w_s = mode_frequencies(h1, m_alpha)
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
        m_alpha=m_alpha,
        h1=h1,
        omega_fast=w_f.real,
        omega_slow=w_s.real,
        growth_rate=abs(w_f.imag),
        stable=h1**2 > 4.0 * m_alpha,
        critical_spin_rpm=2.0 * math.sqrt(m_alpha) / ball.inertia_ratio / RPM,
        equilibrium_sideslip=s3p,
        c1=complex(c1),
        c2=complex(c2),
        omega_v=omega_v,
        speed=speed,
        flight_path_angle=phi,
    )


def local_modes(moment_k: float, air_velocity: np.ndarray, h1, gravity: float = frames.GRAVITY):
    """
    Local linear-theory numbers along a flight (arrays broadcast over samples).

    ``moment_k`` = M_alpha / U^2 [1/m^2], ``air_velocity`` (..., 3) [m/s], ``h1`` [rad/s].
    Returns (w_f, w_s, D, s3p): complex mode frequencies [rad/s] (fast = larger |w|, as
    :func:`mode_frequencies`), D = sqrt(h1^2 - 4 M_alpha) (complex), and the local equilibrium
    sideslip s3p [rad].
    """
    air = np.asarray(air_velocity, dtype=float)
    speed = np.linalg.norm(air, axis=-1)
    phi = frames.flight_path_angle(air)
    m_alpha = moment_k * speed**2
    h1 = np.asarray(h1, dtype=float)
    disc = np.sqrt((h1**2 - 4.0 * m_alpha).astype(complex))
    s3p = gravity * np.cos(phi) * h1 / (m_alpha * speed)
    signed = np.where(h1 < 0.0, -disc, disc)
    return (h1 + signed) / 2.0, (h1 - signed) / 2.0, disc, s3p


def local_exponents(params: np.ndarray, air_velocity: np.ndarray, h1):
    """
    Return the local linear equation x'' + B x' - C x = F of the flown model.

    Kernel ``params`` of :func:`football_ros.physics.dynamics.make_params`; the paper's when
    its extra terms are 0.

    B = fk U C_Lalpha - dk U C_Mq - i (h1 + fk p D C_Npalpha),
    C = M_alpha + h1 fk p D C_Npalpha + i (h1 fk U C_Lalpha + dk U p C_Mpalpha),
    F = (i h1 + dk U C_Mq) w_V, w_V = -g cos(Phi) / U (docs/physics.md section 5), with
    fk = rho S / 2m [1/m], dk = rho S D^2 / (2 I_t) [1/m] (without U, as everywhere in
    docs/physics.md), p = (I_t/I_s) h1. Returns (sigma_1, sigma_2, B,
    D_c, x_p): the exponents (-B +- i D_c) / 2 with D_c = sqrt(-(B^2 + 4C)) (= sqrt(h1^2 -
    4 M_alpha) for the paper: sigma = i w_f, i w_s), and the equilibrium x_p = -F / C.
    """
    air = np.asarray(air_velocity, dtype=float)
    speed = np.linalg.norm(air, axis=-1)
    phi = frames.flight_path_angle(air)
    h1 = np.asarray(h1, dtype=float)
    spin = params[dyn.P_SPIN_RATIO] * h1
    fk, diameter = params[dyn.P_FORCE_K], params[dyn.P_DIAMETER]
    dk_u = params[dyn.P_DAMP_K] * speed
    m_alpha = params[dyn.P_MOMENT_K] * speed**2
    magnus = fk * spin * diameter * params[dyn.P_CNPA]
    b = fk * speed * params[dyn.P_CLA] - dk_u * params[dyn.P_CMQ] - 1j * (h1 + magnus)
    c = (
        m_alpha
        + h1 * magnus
        + 1j * (h1 * fk * speed * params[dyn.P_CLA] + dk_u * spin * params[dyn.P_CMPA])
    )
    d_c = np.sqrt(-(b * b + 4.0 * c))
    w_v = -params[dyn.P_GRAVITY] * np.cos(phi) / speed
    x_p = -(1j * h1 + dk_u * params[dyn.P_CMQ]) * w_v / c
    return (-b + 1j * d_c) / 2.0, (-b - 1j * d_c) / 2.0, b, d_c, x_p


def mode_rates(
    params: np.ndarray,
    speed: float,
    h1: float,
    speed_rate: float | None = None,
    h1_rate: float | None = None,
) -> tuple[complex, complex]:
    """
    Return per-second exponents of the two modes of the full model's linear equation.

    At air speed ``speed`` [m/s] and spin momentum ``h1`` [rad/s] (kernel ``params``), fast
    first.

    Returns (fast, slow): complex, real part the damping rate [1/s] of the mode's amplitude
    (< 0 decays), imaginary part its frequency [rad/s] (fast = larger |frequency|). In the
    time domain, as :func:`quasi_steady_components` builds the flight:

        rate = Re(sigma) - Re(D_c' / D_c) / 2 +- Re(B' / (2 i D_c))

    with sigma, B, D_c of :func:`local_exponents` and B', D_c' from U' = ``speed_rate``
    (default: drag alone, -fk C_D0 U^2) and h1' = ``h1_rate`` (default: spin damping,
    dk U C_lp p). The WKB terms are what McCoy's per-calibre rates lambda U / D miss when p
    is not proportional to U (docs/physics.md section 5).
    """
    a, fk, dk = params[dyn.P_SPIN_RATIO], params[dyn.P_FORCE_K], params[dyn.P_DAMP_K]
    c_la, c_mq, c_np, c_mp = (
        params[dyn.P_CLA],
        params[dyn.P_CMQ],
        params[dyn.P_CNPA],
        params[dyn.P_CMPA],
    )
    diameter, k = params[dyn.P_DIAMETER], params[dyn.P_MOMENT_K]
    u, spin = float(speed), a * h1
    if speed_rate is None:
        speed_rate = -fk * params[dyn.P_CD0] * u * u
    if h1_rate is None:
        h1_rate = dk * u * params[dyn.P_CLP] * spin
    magnus = fk * a * diameter * c_np  # Magnus force term per unit h1
    b = complex(fk * u * c_la - dk * u * c_mq, -(h1 + magnus * h1))
    c = complex(k * u * u + magnus * h1 * h1, h1 * fk * u * c_la + dk * u * spin * c_mp)
    b_dot = (fk * c_la - dk * c_mq) * speed_rate - 1j * (1.0 + magnus) * h1_rate
    c_dot = (
        complex(2.0 * k * u, h1 * fk * c_la + dk * spin * c_mp) * speed_rate
        + complex(2.0 * magnus * h1, fk * u * c_la + dk * u * a * c_mp) * h1_rate
    )
    d_c = cmath.sqrt(-(b * b + 4.0 * c))
    d_c_dot = -(b * b_dot + 2.0 * c_dot) / d_c
    common = -0.5 * (d_c_dot / d_c).real
    wkb = (b_dot / (2j * d_c)).real
    sig1, sig2 = (-b + 1j * d_c) / 2.0, (-b - 1j * d_c) / 2.0
    one = complex(sig1.real + common + wkb, sig1.imag)
    two = complex(sig2.real + common - wkb, sig2.imag)
    return (one, two) if abs(one.imag) >= abs(two.imag) else (two, one)


def scalar_constants(params: np.ndarray) -> tuple:
    """
    Return the kernel parameters the scalar paths read, as a tuple of Python floats.

    From kernel ``params`` (:func:`football_ros.physics.dynamics.make_params`): spin ratio
    I_t/I_s, fk [1/m], dk [1/m], C_Lalpha, C_Mq, diameter [m], C_Npalpha, M_alpha / U^2
    [1/m^2], C_Mpalpha, gravity [m/s^2], C_D0, C_lp, in that order; the ``consts`` of
    :func:`local_exponents_scalar` and :func:`drifting_equilibrium`.
    """
    keys = (
        dyn.P_SPIN_RATIO,
        dyn.P_FORCE_K,
        dyn.P_DAMP_K,
        dyn.P_CLA,
        dyn.P_CMQ,
        dyn.P_DIAMETER,
        dyn.P_CNPA,
        dyn.P_MOMENT_K,
        dyn.P_CMPA,
        dyn.P_GRAVITY,
        dyn.P_CD0,
        dyn.P_CLP,
    )
    return tuple(float(params[k]) for k in keys)


def local_exponents_scalar(consts: tuple, air_velocity, h1: float) -> tuple:
    """
    Return :func:`local_exponents` for one sample, in plain floats (the real-time path).

    ``consts`` from :func:`scalar_constants`, ``air_velocity`` a 3-sequence [m/s] in
    ``field``, ``h1`` [rad/s]. Returns (sigma_1, sigma_2, B, D_c, x_p) as Python complexes.
    Numba compiles it as it stands (the planner's wobble kernel: :mod:`football_ros.planning.
    kernels`).
    """
    spin_ratio, fk, dk, c_la, c_mq = consts[0], consts[1], consts[2], consts[3], consts[4]
    diameter, c_np, moment_k, c_mp, gravity = consts[5], consts[6], consts[7], consts[8], consts[9]
    ux, uy, uz = float(air_velocity[0]), float(air_velocity[1]), float(air_velocity[2])
    speed = math.sqrt(ux * ux + uy * uy + uz * uz)
    cos_phi = math.hypot(ux, uy) / speed
    spin = spin_ratio * h1
    dk_u = dk * speed
    magnus = fk * spin * diameter * c_np
    b = complex(fk * speed * c_la - dk_u * c_mq, -(h1 + magnus))
    c = complex(
        moment_k * speed * speed + h1 * magnus, h1 * fk * speed * c_la + dk_u * spin * c_mp
    )
    d_c = cmath.sqrt(-(b * b + 4.0 * c))
    w_v = -gravity * cos_phi / speed
    x_p = -complex(dk_u * c_mq, h1) * w_v / c
    return (-b + 1j * d_c) / 2.0, (-b - 1j * d_c) / 2.0, b, d_c, x_p


EQUILIBRIUM_STEP = 1e-4
"""Time step [s] of the central difference that gives the equilibrium's drift x_p'."""


def _path_rates(consts: tuple, air, h1):
    """
    U' [m/s^2] and h1' [rad/s^2] of the linearised flight (zero yaw).

    Gravity and drag C_D0 on u, spin damping on h1 (arrays (..., 3) and (...) or plain floats).
    """
    spin_ratio, fk, dk, gravity, c_d0, c_lp = (
        consts[0],
        consts[1],
        consts[2],
        consts[9],
        consts[10],
        consts[11],
    )
    air = np.asarray(air, dtype=float)
    speed = np.linalg.norm(air, axis=-1)
    u_dot = -fk * c_d0 * speed[..., None] * air if air.ndim > 1 else -fk * c_d0 * speed * air
    u_dot = u_dot - np.array([0.0, 0.0, gravity])
    return u_dot, dk * speed * c_lp * spin_ratio * h1


def drifting_equilibrium(exponents, consts, air, h1, b, d_c, x_p):
    """
    Return the equilibrium to first order in its drift, and that drift: (x_p + B x_p'/C, x_p').

    Inserting x = x_p(t) + y in x'' + B x' - C x = F leaves B x_p' on the right; its
    quasi-static answer is y = B x_p' / C. x_p' [1/s] is a central difference of
    ``exponents`` (``exponents(air, h1)``: :func:`local_exponents` or the scalar twin) along
    the linearised path rates. ``consts`` from :func:`scalar_constants`; ``air`` [m/s]
    (..., 3) in ``field`` and ``h1`` [rad/s] the samples, ``b``, ``d_c``, ``x_p`` their
    :func:`local_exponents`.
    """
    u_dot, h1_dot = _path_rates(consts, air, h1)
    eps = EQUILIBRIUM_STEP
    air = np.asarray(air, dtype=float)
    ahead = exponents(air + eps * u_dot, h1 + eps * h1_dot)[4]
    behind = exponents(air - eps * u_dot, h1 - eps * h1_dot)[4]
    x_p_dot = (ahead - behind) / (2.0 * eps)
    c = -(b * b + d_c * d_c) / 4.0
    return x_p + b * x_p_dot / c, x_p_dot


def drifting_equilibrium_scalar(consts: tuple, air, h1: float, b, d_c, x_p):
    """
    Return :func:`drifting_equilibrium` for one sample in plain floats (X_p, x_p').

    ``air`` a 3-sequence [m/s] in ``field``, ``h1`` [rad/s], ``b``, ``d_c``, ``x_p`` its
    :func:`local_exponents_scalar`; the exponents along the path by
    :func:`local_exponents_scalar`. The vectorised path's operations in its order (the same
    numbers); Python complexes.
    """
    air_ahead, h1_ahead, air_behind, h1_behind = drift_points(consts, air, h1)
    return drift_of(b, d_c, x_p, local_exponents_scalar(consts, air_ahead, h1_ahead)[4],
                    local_exponents_scalar(consts, air_behind, h1_behind)[4])


def drift_points(consts: tuple, air, h1: float) -> tuple:
    """
    Return the samples of the drift's central difference: (air, h1) ahead, then behind.

    ``EQUILIBRIUM_STEP`` along the linearised path rates (:func:`_path_rates`: gravity and
    drag C_D0 on the air velocity, spin damping on h1) from ``air`` [m/s] (3-sequence, in
    ``field``) and ``h1`` [rad/s]; air velocities as 3-tuples. Numba compiles it as it stands.
    """
    spin_ratio, fk, dk = consts[0], consts[1], consts[2]
    gravity, c_d0, c_lp = consts[9], consts[10], consts[11]
    ux, uy, uz = float(air[0]), float(air[1]), float(air[2])
    speed = math.sqrt(ux * ux + uy * uy + uz * uz)
    drag = -fk * c_d0 * speed
    dx, dy, dz = drag * ux - 0.0, drag * uy - 0.0, drag * uz - gravity
    h1_dot = dk * speed * c_lp * spin_ratio * h1
    eps = EQUILIBRIUM_STEP
    return ((ux + eps * dx, uy + eps * dy, uz + eps * dz), h1 + eps * h1_dot,
            (ux - eps * dx, uy - eps * dy, uz - eps * dz), h1 - eps * h1_dot)


def drift_of(b, d_c, x_p, x_p_ahead, x_p_behind) -> tuple:
    """
    Return (X_p, x_p') of :func:`drifting_equilibrium` from x_p at :func:`drift_points`.

    ``b``, ``d_c``, ``x_p``: :func:`local_exponents_scalar` at the sample, ``x_p_ahead`` and
    ``x_p_behind`` its x_p at the two points. Numba compiles it as it stands.
    """
    x_p_dot = (x_p_ahead - x_p_behind) / (2.0 * EQUILIBRIUM_STEP)
    c = -(b * b + d_c * d_c) / 4.0
    return x_p + b * x_p_dot / c, x_p_dot


def mode_amplitudes(
    modes: LinearModes, sigma_1, sigma_2, x_p0, x_p_dot0=0.0
) -> tuple[complex, complex]:
    """
    Return mode amplitudes for the release state of ``modes`` (x0, x0').

    Also the local exponents and the equilibrium x_p0 and its rate x_p_dot0 at release.
    """
    w_f, w_s = modes._roots()
    x0 = modes.c1 + modes.c2 + 1j * modes.equilibrium_sideslip
    x0_dot = 1j * w_f * modes.c1 + 1j * w_s * modes.c2 - x_p_dot0
    k1 = (x0_dot - sigma_2 * (x0 - x_p0)) / (sigma_1 - sigma_2)
    k2 = (sigma_1 * (x0 - x_p0) - x0_dot) / (sigma_1 - sigma_2)
    return complex(k1), complex(k2)


def quasi_steady_components(
    modes: LinearModes, params: np.ndarray, times: np.ndarray, air_velocities: np.ndarray, h1
) -> np.ndarray:
    """
    Return x(t) = s2 + i s3 of the quasi-steady linear theory at ``times`` [s].

    ``times`` increasing, the first one the release; from the flight's air-relative velocities
    (N, 3) [m/s] and h1.

    x = A1 K1 exp(int sigma_1) + A2 K2 exp(int sigma_2) + X_p(t) with the local exponents of
    :func:`local_exponents`, the equilibrium to the same (first) order as the amplitudes,
    X_p = x_p + B x_p' / C (x_p = -F/C), K1, K2 from the release state (x0 - X_p, x0' - x_p'),
    and the first-order WKB amplitudes ln A_1,2 = -ln(D_c / D_c(0)) / 2 +- int dB / (2 i D_c).
    Integrals by the trapezoid rule over the samples (error ~ dt^2 times the second derivative
    of the rates).
    """
    times = np.asarray(times, dtype=float)
    h1 = np.broadcast_to(h1, times.shape)
    sig1, sig2, b, d_c, x_p = local_exponents(params, air_velocities, h1)
    x_p, x_p_dot = drifting_equilibrium(
        lambda air, h: local_exponents(params, air, h),
        scalar_constants(params),
        air_velocities,
        h1,
        b,
        d_c,
        x_p,
    )
    k1, k2 = mode_amplitudes(modes, sig1[0], sig2[0], x_p[0], x_p_dot[0])
    dt = np.diff(times)

    def integral(f, df=None):
        steps = 0.5 * (f[1:] + f[:-1]) * (dt if df is None else df)
        return np.concatenate([[0.0], np.cumsum(steps)])

    drift = integral(1.0 / (2j * d_c), np.diff(b))
    common = np.sqrt(d_c[0] / d_c)
    with np.errstate(over='ignore', invalid='ignore'):
        modes_part = k1 * np.exp(integral(sig1) + drift) + k2 * np.exp(integral(sig2) - drift)
        return common * modes_part + x_p
