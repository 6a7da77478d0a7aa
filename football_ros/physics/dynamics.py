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
Equations of motion and their integrator: the hot path, compiled with numba.

Torque-only model of the paper (docs/physics.md, "The paper's model"), in ``field``:

    r' = v,  v' = (0, 0, -g),  h' = M_alpha(V) f(delta) (v_hat x s),  s' = h x s

with M_alpha(V) = k V^2, f = 1 (``linear``) or cos(delta) (``sin2delta``, Rae & Streit's
C_M = 0.165 sin 2 delta scaled by C_Malpha / 0.33). The full model adds the forces and moments
of :mod:`football_ros.physics.aero` (all in :func:`loads`); with its coefficients zero the
added terms are exact zeros.

State vector (``N_STATE`` floats): position r [m], velocity v [m/s], the attitude quaternion
q_nr (x, y, z, w) of a frame that carries the axis (body x = s) without rolling (it turns with
w_perp only), the modified angular momentum h = H / I_t [rad/s], the spin momentum h1 = h.s
[rad/s] and the spin angle phi [rad] of the ball about s relative to that frame. The ball's
orientation is q_nr * rot_x(phi); phi' = p = (I_t/I_s) h1.

The step is classical RK4 followed by a projection: q_nr is normalised (so |s| = 1) and h is
corrected along s so that h.s equals the integrated h1 (constant in the paper's model; the full
model's spin damping changes it through dh1/dt, which RK4 integrates like the other states).
Both invariants hold to round-off for any step size.
"""

from __future__ import annotations

import math

from numba import njit
import numpy as np

from .model_params import (  # noqa: F401  (the layout, re-exported for the kernels' users)
    H,
    H1,
    make_params,
    N_PARAM,
    N_STATE,
    P_CD0,
    P_CD2,
    P_CLA,
    P_CLP,
    P_CMPA,
    P_CMQ,
    P_CNPA,
    P_DAMP_K,
    P_DIAMETER,
    P_FORCE_K,
    P_GRAVITY,
    P_MOMENT_K,
    P_SIN2DELTA,
    P_SPIN_RATIO,
    P_WIND,
    PHI,
    Q,
    R,
    V,
)


@njit(cache=True)
def axis_of(y: np.ndarray) -> tuple:
    """Spin axis s = body x of q_nr."""
    qx, qy, qz, qw = y[Q], y[Q + 1], y[Q + 2], y[Q + 3]
    return (1.0 - 2.0 * (qy * qy + qz * qz), 2.0 * (qx * qy + qw * qz), 2.0 * (qx * qz - qw * qy))


@njit(cache=True, inline='always')
def loads(v: tuple, s: tuple, h: tuple, h1: float, params: np.ndarray) -> tuple:
    """
    Return acceleration a [m/s^2], dh/dt [rad/s^2] and dh1/dt of the ball.

    The module docstring and :mod:`football_ros.physics.aero` give the terms. Shared by every
    kernel.
    """
    vx, vy, vz = v
    sx, sy, sz = s
    hx, hy, hz = h
    ux, uy, uz = vx - params[P_WIND], vy - params[P_WIND + 1], vz - params[P_WIND + 2]
    speed = math.sqrt(ux * ux + uy * uy + uz * uz)
    ex, ey, ez = ux / speed, uy / speed, uz / speed
    cos_d = ex * sx + ey * sy + ez * sz
    cx, cy, cz = ey * sz - ez * sy, ez * sx - ex * sz, ex * sy - ey * sx  # u_hat x s
    # Overturning moment (the paper): h' = k U^2 f(delta) (u_hat x s), f = 1 or cos(delta).
    # No branches below: zero coefficients give exact zeros, and the batch kernel vectorises.
    flag = params[P_SIN2DELTA]
    gain = params[P_MOMENT_K] * speed * speed * (1.0 - flag + flag * cos_d)
    fk = params[P_FORCE_K]
    spin = params[P_SPIN_RATIO] * h1
    q_u2 = fk * speed * speed
    drag = -q_u2 * (params[P_CD0] + params[P_CD2] * (1.0 - cos_d * cos_d))
    lift = q_u2 * params[P_CLA] * cos_d  # C_L = C_Lalpha/2 sin 2 delta (Rae & Streit's form)
    # Magnus force along s x u_hat = -(u_hat x s): classical direction for C_Npalpha > 0.
    magnus = -fk * speed * spin * params[P_DIAMETER] * params[P_CNPA]
    ax = drag * ex + lift * (sx - cos_d * ex) + magnus * cx
    ay = drag * ey + lift * (sy - cos_d * ey) + magnus * cy
    az = drag * ez + lift * (sz - cos_d * ez) + magnus * cz - params[P_GRAVITY]
    dk = params[P_DAMP_K] * speed
    hs = hx * sx + hy * sy + hz * sz
    pitch = dk * params[P_CMQ]
    roll = dk * params[P_CLP] * spin
    mag_m = dk * spin * params[P_CMPA]
    dhx = gain * cx + pitch * (hx - hs * sx) + roll * sx + mag_m * (ex - cos_d * sx)
    dhy = gain * cy + pitch * (hy - hs * sy) + roll * sy + mag_m * (ey - cos_d * sy)
    dhz = gain * cz + pitch * (hz - hs * sz) + roll * sz + mag_m * (ez - cos_d * sz)
    dh1 = roll
    return ax, ay, az, dhx, dhy, dhz, dh1


@njit(cache=True)
def derivative(y: np.ndarray, params: np.ndarray, out: np.ndarray) -> None:
    """Write dy/dt into ``out`` (autonomous: the model has no explicit time)."""
    s = axis_of(y)
    sx, sy, sz = s
    hx, hy, hz = y[H], y[H + 1], y[H + 2]
    ax, ay, az, dhx, dhy, dhz, dh1 = loads(
        (y[V], y[V + 1], y[V + 2]), s, (hx, hy, hz), y[H1], params
    )
    # Transverse angular velocity w_perp = h - (h.s) s turns the non-rolling frame.
    hs = hx * sx + hy * sy + hz * sz
    wx, wy, wz = hx - hs * sx, hy - hs * sy, hz - hs * sz
    qx, qy, qz, qw = y[Q], y[Q + 1], y[Q + 2], y[Q + 3]
    out[R], out[R + 1], out[R + 2] = y[V], y[V + 1], y[V + 2]
    out[V], out[V + 1], out[V + 2] = ax, ay, az
    out[Q] = 0.5 * (wx * qw + wy * qz - wz * qy)
    out[Q + 1] = 0.5 * (-wx * qz + wy * qw + wz * qx)
    out[Q + 2] = 0.5 * (wx * qy - wy * qx + wz * qw)
    out[Q + 3] = 0.5 * (-wx * qx - wy * qy - wz * qz)
    out[H], out[H + 1], out[H + 2] = dhx, dhy, dhz
    out[H1] = dh1
    out[PHI] = params[P_SPIN_RATIO] * y[H1]


@njit(cache=True)
def project_invariants(y: np.ndarray) -> None:
    """
    Project a state onto the invariants of the exact flow, in place.

    Normalises q_nr and makes h.s equal h1 (the step's last act: :func:`rk4_step_with`).
    """
    norm = math.sqrt(y[Q] ** 2 + y[Q + 1] ** 2 + y[Q + 2] ** 2 + y[Q + 3] ** 2)
    for i in range(4):
        y[Q + i] /= norm
    sx, sy, sz = axis_of(y)
    err = y[H1] - (y[H] * sx + y[H + 1] * sy + y[H + 2] * sz)
    y[H] += err * sx
    y[H + 1] += err * sy
    y[H + 2] += err * sz


@njit(cache=True)
def rk4_step_with(
    y: np.ndarray, dt: float, params: np.ndarray, out: np.ndarray, work: np.ndarray
) -> None:
    """
    One RK4 step of ``dt`` [s] from ``y`` into ``out`` (may alias ``y``), then projected.

    ``work`` (5, N_STATE): caller-owned scratch (no allocation). The package's one RK4 step.
    """
    n = y.size
    k1, k2, k3, k4, tmp = work[0], work[1], work[2], work[3], work[4]
    derivative(y, params, k1)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * dt * k1[i]
    derivative(tmp, params, k2)
    for i in range(n):
        tmp[i] = y[i] + 0.5 * dt * k2[i]
    derivative(tmp, params, k3)
    for i in range(n):
        tmp[i] = y[i] + dt * k3[i]
    derivative(tmp, params, k4)
    for i in range(n):
        out[i] = y[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    project_invariants(out)


@njit(cache=True)
def advance(y: np.ndarray, n_steps: int, dt: float, params: np.ndarray) -> None:
    """Take ``n_steps`` RK4 steps of ``dt`` in place."""
    work = np.empty((5, y.size))
    for _ in range(n_steps):
        rk4_step_with(y, dt, params, y, work)


@njit(cache=True)
def landing_time_in_step(y: np.ndarray, dt: float, params: np.ndarray, ground: float) -> float:
    """Time [s] in [0, dt] at which z reaches ``ground`` in the step from ``y`` (bisection)."""
    lo, hi = 0.0, dt
    tmp = np.empty(y.size)
    work = np.empty((5, y.size))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        rk4_step_with(y, mid, params, tmp, work)
        if tmp[R + 2] > ground:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def crossed_ground(before: np.ndarray, after: np.ndarray, ground: float) -> bool:
    """
    Tell whether a step took the ball from at or above ``ground`` to at or below it, moving down.

    "At" counts too: a release from the ground that the air pushes down at once (a strong
    downdraft, a steep lift) lands in its first step instead of flying on below ground.
    """
    return before[R + 2] >= ground and after[R + 2] <= ground and after[V + 2] < 0.0


@njit(cache=True, nogil=True)
def march(
    y: np.ndarray, done: int, target: int, dt: float, params: np.ndarray, ground: float,
    nxt: np.ndarray, work: np.ndarray,
) -> tuple:
    """
    Whole RK4 steps of ``dt`` [s] in place from ``y`` (``done`` steps flown) up to ``target``.

    Stops early, before the step that would cross z = ``ground`` moving down. Returns (steps
    flown, crossed). ``nxt`` (N_STATE,), ``work`` (5, N_STATE): caller-owned scratch. The one
    march every fixed-step flight takes (:class:`~football_ros.physics.flight.Flight`,
    :func:`propagate`, the simulator's many-ball kernel).
    """
    while done < target:
        rk4_step_with(y, dt, params, nxt, work)
        if crossed_ground(y, nxt, ground):
            return done, True
        y[:] = nxt
        done += 1
    return done, False


@njit(cache=True, nogil=True)
def finish(
    y: np.ndarray, rest: float, params: np.ndarray, ground: float, crossed: bool,
    out: np.ndarray, work: np.ndarray,
) -> float:
    """
    Take the partial step of ``rest`` [s] from a marched ``y`` into ``out``, or land.

    Returns NaN, or the landing's time [s] after ``y`` when the step crosses z = ``ground``
    (``crossed``: :func:`march` found that the next whole step does): ``out`` is then the
    landing state (z = ground exactly).
    """
    if not crossed:
        rk4_step_with(y, rest, params, out, work)
        if not crossed_ground(y, out, ground):
            return math.nan
    tau = landing_time_in_step(y, rest, params, ground)
    rk4_step_with(y, tau, params, out, work)
    out[R + 2] = ground
    return tau


@njit(cache=True, nogil=True)  # the release node predicts beside its executor
def propagate(
    y0: np.ndarray,
    dt: float,
    params: np.ndarray,
    sample_period: float,
    duration: float,
    ground: float,
) -> tuple:
    """
    Integrate from ``y0`` at t = 0 and sample at multiples of ``sample_period`` [s].

    Stops at ``duration`` or when the ball, moving down, reaches z = ``ground``; the last
    sample is then the landing, located to round-off inside its step. Integration steps are
    ``dt`` [s]; a sample between steps is a partial step from the last whole one, so samples
    do not change the trajectory. Returns (times, states, landed).
    """
    n_max = int(math.floor(duration / sample_period + 1e-9)) + 1
    times = np.empty(n_max)
    states = np.empty((n_max, y0.size))
    y = y0.copy()
    nxt = np.empty(y0.size)
    work = np.empty((5, y0.size))
    n_steps = 0
    for k in range(n_max):
        t_sample = k * sample_period
        target = int(math.floor((t_sample + 1e-12) / dt))
        while (target + 1) * dt <= t_sample + 1e-12:  # the float test decides, as it always did
            target += 1
        while target > 0 and target * dt > t_sample + 1e-12:
            target -= 1
        n_steps, crossed = march(y, n_steps, target, dt, params, ground, nxt, work)
        rest = dt if crossed else t_sample - n_steps * dt
        tau = finish(y, rest, params, ground, crossed, states[k], work)
        if not math.isnan(tau):
            times[k] = n_steps * dt + tau
            return times[: k + 1], states[: k + 1], True
        times[k] = t_sample
    return times, states, False


@njit(cache=True)
def velocity_frame_components(v: tuple, s: tuple) -> tuple:
    """
    Return components (s1, s2, s3) of ``s`` along e1, e2, e3.

    e1 = v/V, e2 = up made perpendicular to e1 and e3 = e1 x e2 (compiled twin of
    :func:`football_ros.physics.frames.to_velocity_frame`). Pass the air-relative velocity v -
    wind for aerodynamic angles.
    """
    vx, vy, vz = v
    sx, sy, sz = s
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    e1x, e1y, e1z = vx / speed, vy / speed, vz / speed
    e2x, e2y, e2z = -e1z * e1x, -e1z * e1y, 1.0 - e1z * e1z
    n2 = math.sqrt(e2x * e2x + e2y * e2y + e2z * e2z)
    e2x, e2y, e2z = e2x / n2, e2y / n2, e2z / n2
    e3x, e3y, e3z = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    return (
        sx * e1x + sy * e1y + sz * e1z,
        sx * e2x + sy * e2y + sz * e2z,
        sx * e3x + sy * e3y + sz * e3z,
    )


# Columns of describe(): orientation (x, y, z, w), axis, angular velocity, alpha, beta, delta.
D_ORIENT, D_AXIS, D_OMEGA, D_ALPHA, D_BETA, D_DELTA = 0, 4, 7, 10, 11, 12
N_DESCRIBE = 13


@njit(cache=True)
def describe(states: np.ndarray, params: np.ndarray) -> np.ndarray:
    """
    Derive quantities of state rows (N, N_STATE) -> (N, N_DESCRIBE), in ``field``.

    Orientation = q_nr * rot_x(phi) (body x = axis, spin angle included); angular velocity
    w = h - h1 s + p s with p = (I_t/I_s) h1; alpha, beta, delta as in docs/physics.md,
    against the air-relative velocity v - wind (wind from ``params``; the ground velocity when
    there is none). Compiled twin of :func:`football_ros.physics.frames.aero_angles`.
    """
    out = np.empty((states.shape[0], N_DESCRIBE))
    for i in range(states.shape[0]):
        y = states[i]
        sx, sy, sz = axis_of(y)
        half = 0.5 * y[PHI]
        c, s = math.cos(half), math.sin(half)
        qx, qy, qz, qw = y[Q], y[Q + 1], y[Q + 2], y[Q + 3]
        out[i, D_ORIENT] = qw * s + qx * c
        out[i, D_ORIENT + 1] = qy * c + qz * s
        out[i, D_ORIENT + 2] = qz * c - qy * s
        out[i, D_ORIENT + 3] = qw * c - qx * s
        out[i, D_AXIS], out[i, D_AXIS + 1], out[i, D_AXIS + 2] = sx, sy, sz
        extra = params[P_SPIN_RATIO] * y[H1] - y[H1]
        out[i, D_OMEGA] = y[H] + extra * sx
        out[i, D_OMEGA + 1] = y[H + 1] + extra * sy
        out[i, D_OMEGA + 2] = y[H + 2] + extra * sz
        air = (y[V] - params[P_WIND], y[V + 1] - params[P_WIND + 1], y[V + 2] - params[P_WIND + 2])
        s1, s2, s3 = velocity_frame_components(air, (sx, sy, sz))
        out[i, D_ALPHA] = math.atan2(s2, s1)
        out[i, D_BETA] = math.asin(min(1.0, max(-1.0, s3)))
        out[i, D_DELTA] = math.acos(min(1.0, max(-1.0, s1)))
    return out
