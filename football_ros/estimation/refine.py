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
Batch MAP refinement of a tracked throw: every fix of the track fitted at once.

Why: the unscented filter forgets. Its process noise (the model-error allowance) and its one
linearisation per fix cost information that the fixes hold, most where the fixes are precise
(5 mm) or the ball tumbles; a batch fit of the deterministic flight to all the fixes, with the
filter's own prior, is what reaches the information bound (:mod:`.bound`;
bench/prediction_bound.py's MAP and tracker rows).

The unknown is the state at the track's first fix, time ``times[0]`` (``N_X`` or ``N_X_WIND``
floats, :mod:`.motion`), moved by a local step delta: position and velocity [m, m/s], two
angles [rad] turning the axis in its tangent plane, h [rad/s] in ``field``, kd, kl and the
wind [m/s] if the state has it. The objective is
sum_k |L_k^-1 (h_k(r(t_k)) - z_k)|^2 (each fix's model h_k and covariance L_k L_k',
:mod:`.measurement`) + the prior's terms (:class:`Prior`, as the filter starts:
the axis off the velocity by N(0, axis_sigma) per angle, the spin momentum h.s and the
transverse momentum, the scales and the wind), minimised by Levenberg-Marquardt steps with a
forward-difference Jacobian whose n + 1 states are flown together
(:func:`.motion.fly_through`). The posterior is the Laplace one at the fit, handed back as the
state and its covariance at the last fix (the fit flown there, the covariance carried by the
Jacobian's own flights), the form the
filter's predictions take.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from numba import njit
import numpy as np

from .measurement import Measurement, position_fix, Whitener
from .motion import fly_state, fly_through, N_X_WIND, X_H, X_KD, X_KL, X_R, X_S, X_V, X_W

FD_STEP = np.array(
    [1e-4] * 3 + [1e-4] * 3 + [1e-5] * 2 + [1e-3] * 3 + [1e-4] * 2 + [1e-3] * 2
)
"""Forward-difference step per entry of delta (m, m/s, rad, rad/s, 1, m/s)."""
CONVERGED = 0.01
"""A step that lowers the objective (a chi-square) by less ends the fit: it moved the estimate by
about a tenth of its sigma (sqrt of the decrease), what is left to the minimum far less."""


@dataclass(frozen=True)
class Prior:
    """
    The filter's prior at the track's first fix (SI).

    ``h1`` (mean, sigma) of the spin momentum h.s [rad/s] (signed: the hand); ``axis_sigma``
    [rad] of each angle between the axis and the velocity; ``rate_sigma`` [rad/s] of each
    transverse component of h; ``states`` (index, mean, sigma) of single state entries: the
    drag and lift scales, and the wind [m/s] where the state has it.
    """

    h1: tuple[float, float]
    axis_sigma: float
    rate_sigma: float
    states: tuple[tuple[int, float, float], ...]


@dataclass(frozen=True)
class Refined:
    """
    A batch fit.

    ``x0`` the MAP state at the first fix, ``x`` (n_x,) and ``P`` (n_x, n_x) the posterior's
    at the last fix, ``cost`` the objective at the fit (chi-square of the fixes plus the
    prior's terms), ``iterations`` taken, ``logdet`` the log-determinant of the posterior's
    covariance of the step delta at the first fix (units of :data:`FD_STEP`): with ``cost``,
    the Laplace evidence of the fit's prior, -cost / 2 + logdet / 2 + a constant that two fits
    of the same fixes and step share; ``converged`` whether a step's decrease fell below
    :data:`CONVERGED` or no step lowered the objective (False: the iterations ran out);
    ``dof`` the objective's degrees of freedom, its whitened residuals less the unknowns (a
    fit in the right basin has ``cost`` near it: chi-square).
    """

    x0: np.ndarray
    x: np.ndarray
    P: np.ndarray
    cost: float
    iterations: int
    logdet: float = math.nan
    converged: bool = True
    dof: int = 0


@njit(cache=True, error_model='numpy')
def _basis(ux: float, uy: float, uz: float) -> tuple:
    """Two unit vectors completing the unit u, as 3-tuples (continuous away from u = +/- z)."""
    ax, ay, az = (0.0, 0.0, 1.0) if abs(uz) < 0.9 else (1.0, 0.0, 0.0)
    b1x, b1y, b1z = ay * uz - az * uy, az * ux - ax * uz, ax * uy - ay * ux
    norm = math.sqrt(b1x * b1x + b1y * b1y + b1z * b1z)
    b1x, b1y, b1z = b1x / norm, b1y / norm, b1z / norm
    return (b1x, b1y, b1z), (uy * b1z - uz * b1y, uz * b1x - ux * b1z, ux * b1y - uy * b1x)


@njit(cache=True, error_model='numpy')
def _apply(x: np.ndarray, deltas: np.ndarray) -> np.ndarray:
    """
    States (m, n_x): ``x`` moved by each row of ``deltas`` (m, n_delta).

    Position, velocity, h, the drag and lift scales (and the wind) add; the axis turns by the
    two angles about a basis completing it, renormalised.
    """
    m = deltas.shape[0]
    out = np.empty((m, x.size))
    b1, b2 = _basis(x[X_S], x[X_S + 1], x[X_S + 2])
    for i in range(m):
        out[i] = x
        for j in range(3):
            out[i, X_R + j] += deltas[i, j]
            out[i, X_V + j] += deltas[i, 3 + j]
            out[i, X_H + j] += deltas[i, 8 + j]
        sx = x[X_S] + deltas[i, 6] * b1[0] + deltas[i, 7] * b2[0]
        sy = x[X_S + 1] + deltas[i, 6] * b1[1] + deltas[i, 7] * b2[1]
        sz = x[X_S + 2] + deltas[i, 6] * b1[2] + deltas[i, 7] * b2[2]
        norm = math.sqrt(sx * sx + sy * sy + sz * sz)
        out[i, X_S], out[i, X_S + 1], out[i, X_S + 2] = sx / norm, sy / norm, sz / norm
        out[i, X_KD] += deltas[i, 11]
        out[i, X_KL] += deltas[i, 12]
        if x.size >= N_X_WIND:
            out[i, X_W] += deltas[i, 13]
            out[i, X_W + 1] += deltas[i, 14]
    return out


@njit(cache=True, error_model='numpy')
def _prior_terms(states: np.ndarray, spin: np.ndarray, index: np.ndarray,
                 entries: np.ndarray) -> np.ndarray:
    """
    Whitened prior residuals (m, 5 + len(index)) of states (m, n_x) at the first fix.

    ``spin``: the axis sigma, h1's mean and sigma and the transverse rate sigma
    (:class:`Prior`); ``index`` the state entries with a prior, ``entries`` (len(index), 2)
    their means and sigmas. Columns: the axis's two angles to the velocity (about the velocity
    frame: horizontal-up, then across), h1 = h.s, the two transverse components of h in one
    basis completing the first row's axis, then each entry.
    """
    m = states.shape[0]
    out = np.empty((m, 5 + index.size))
    axis_sigma, h1_mean, h1_sigma, rate_sigma = spin[0], spin[1], spin[2], spin[3]
    b1, b2 = _basis(states[0, X_S], states[0, X_S + 1], states[0, X_S + 2])
    for i in range(m):
        # The velocity frame as dynamics.velocity_frame_components builds it, inline: that
        # kernel raises ZeroDivisionError on a vertical or zero velocity (numba's Python error
        # model), where the fit wants NaN (a step refused or no fit, as with numpy's terms).
        vx, vy, vz = states[i, X_V], states[i, X_V + 1], states[i, X_V + 2]
        sx, sy, sz = states[i, X_S], states[i, X_S + 1], states[i, X_S + 2]
        hx, hy, hz = states[i, X_H], states[i, X_H + 1], states[i, X_H + 2]
        speed = math.sqrt(vx * vx + vy * vy + vz * vz)
        vx, vy, vz = vx / speed, vy / speed, vz / speed
        e2x, e2y, e2z = -vz * vx, -vz * vy, 1.0 - vz * vz
        norm = math.sqrt(e2x * e2x + e2y * e2y + e2z * e2z)
        e2x, e2y, e2z = e2x / norm, e2y / norm, e2z / norm
        e3x, e3y, e3z = vy * e2z - vz * e2y, vz * e2x - vx * e2z, vx * e2y - vy * e2x
        h1 = hx * sx + hy * sy + hz * sz
        px, py, pz = hx - h1 * sx, hy - h1 * sy, hz - h1 * sz
        out[i, 0] = (sx * e2x + sy * e2y + sz * e2z) / axis_sigma
        out[i, 1] = (sx * e3x + sy * e3y + sz * e3z) / axis_sigma
        out[i, 2] = (h1 - h1_mean) / h1_sigma
        out[i, 3] = (px * b1[0] + py * b1[1] + pz * b1[2]) / rate_sigma
        out[i, 4] = (px * b2[0] + py * b2[1] + pz * b2[2]) / rate_sigma
        for j in range(index.size):
            out[i, 5 + j] = (states[i, index[j]] - entries[j, 0]) / entries[j, 1]
    return out


def warm_up(x: np.ndarray) -> None:
    """Load (or compile) the fit's own kernels for filter states like ``x`` (n_x,)."""
    n_delta = 15 if x.size >= N_X_WIND else 13
    points = _apply(np.ascontiguousarray(x, dtype=float), np.zeros((2, n_delta)))
    _prior_terms(points, np.ones(4), np.array([X_KD], dtype=np.int64), np.array([[1.0, 0.1]]))


def _residuals(states, rel, whiten, params, step, prior_arrays):
    """Whitened residuals (m, n_fix + n_prior) of states at the first fix (end: at the last)."""
    prior = _prior_terms(states, *prior_arrays)  # before the flights move the states on
    out = np.empty((states.shape[0], rel.size, 3))
    fly_through(states, rel, params, step, out)
    return np.concatenate([whiten(out), prior], axis=1)


def refine(
    times: np.ndarray,
    zs: np.ndarray,
    x0: np.ndarray,
    prior: Prior,
    noise: float,
    params: np.ndarray,
    step: float,
    max_iterations: int = 8,
    secant: bool = False,
) -> Refined | None:
    """
    Fit the throw to every fix (batch MAP) from ``x0``, the state at ``times[0]``.

    ``times`` (K,) [s] ascending; ``zs`` the fixes: (K, 3) positions [m] in ``field`` of
    1-sigma ``noise`` [m] per axis, or K :class:`~.measurement.Measurement` (each with its own
    covariance and model; ``noise`` unused); ``params`` the motion kernel's parameters,
    ``step`` [s] its longest RK4 step. Levenberg-Marquardt from ``x0`` until a step lowers the
    objective by less than :data:`CONVERGED`, no step lowers it, or ``max_iterations``
    steps. ``secant``: after the first, the Jacobian is carried by Broyden's rank-one update
    from each accepted step's own flight (one flight a step instead of n + 1), and flown
    afresh only when no step lowers the objective and at the end (the posterior's); for a
    search from many cold starts, whose steps are many and far from the minimum. At
    ``times[-1]``: the fit flown there, and the posterior's covariance carried there by the
    derivatives of the Jacobian's flights (linear: the posterior is narrow). None if a fix or a
    flight is not finite, or the information matrix is singular.
    """
    times = np.asarray(times, dtype=float)
    if not all(isinstance(z, Measurement) for z in zs):
        zs = np.asarray(zs, dtype=float)
        if not np.all(np.isfinite(zs)):
            return None
        zs = [position_fix(z, noise=noise) for z in zs]
    whiten = Whitener(zs)
    prior_arrays = (
        np.array([prior.axis_sigma, prior.h1[0], prior.h1[1], prior.rate_sigma]),
        np.array([i for i, _, _ in prior.states], dtype=np.int64),
        np.array([(mean, sigma) for _, mean, sigma in prior.states], dtype=float).reshape(-1, 2),
    )
    rel = times - times[0]
    n = 15 if x0.size >= N_X_WIND else 13
    steps = FD_STEP[:n]
    fd = np.vstack([np.zeros(n), np.diag(steps)])  # x, then x moved along each delta

    def linearise(x: np.ndarray):
        """(residuals at x, their Jacobian (m, n), d x(times[-1]) / d delta (n, n_x)) or None."""
        pts = _apply(x, fd)
        res = _residuals(pts, rel, whiten, params, step, prior_arrays)  # pts: at the last
        if not (np.all(np.isfinite(res)) and np.all(np.isfinite(pts))):
            return None
        return res[0], ((res[1:] - res[0]) / steps[:, None]).T, (pts[1:] - pts[0]) / steps[:, None]

    x = np.asarray(x0, dtype=float).copy()
    lin = linearise(x)
    if lin is None:
        return None
    r0, jac = lin[:2]
    carried = False  # jac carried by secant updates since the last flown one
    lam, it, cost, converged = 1e-3, 0, math.inf, False
    while it < max_iterations:
        it += 1
        cost, g, info = float(r0 @ r0), jac.T @ r0, jac.T @ jac
        new, trial = math.inf, x
        while lam < 1e8:  # Levenberg-Marquardt: shorten the step until the objective falls
            try:
                d = np.linalg.solve(info + lam * np.diag(np.diag(info)), -g)
            except np.linalg.LinAlgError:
                return None
            trial = _apply(x, d[None, :])
            rt = _residuals(trial.copy(), rel, whiten, params, step, prior_arrays)[0]
            new = float(rt @ rt) if np.all(np.isfinite(rt)) else math.inf
            if new < cost:
                break
            lam *= 4.0
        if new >= cost:  # no step lowers it: at the minimum, unless the Jacobian was carried
            if carried:
                lin = linearise(x)
                if lin is None:
                    return None
                (r0, jac), carried, lam = lin[:2], False, 1e-3
                continue
            converged = True
            break
        x, lam, cost = trial[0], max(lam / 4.0, 1e-7), new
        if r0 @ r0 - new <= CONVERGED:  # the last Jacobian serves the posterior
            converged = True
            break
        if secant:  # Broyden: the Jacobian that maps this step onto its change of residuals
            jac = jac + np.outer(rt - r0 - jac @ d, d / (d @ d))
            r0, carried = rt, True
        else:
            lin = linearise(x)
            if lin is None:
                return None
            r0, jac = lin[:2]
    if carried:  # the posterior's Jacobian flown, at the fit
        lin = linearise(x)
        if lin is None:
            return None
    jac, ends = lin[1], lin[2]  # the posterior at the fit: Laplace, (J'J)^-1 in delta
    info = jac.T @ jac
    d = np.sqrt(np.diag(info))
    if not (np.all(d > 0.0) and np.all(np.isfinite(d))):
        return None
    try:
        cov = np.linalg.inv(info / np.outer(d, d)) / np.outer(d, d)
        logdet = -float(np.linalg.slogdet(info / np.outer(d, d))[1]) - 2.0 * float(
            np.sum(np.log(d))
        )
    except np.linalg.LinAlgError:
        return None
    mode = fly_state(x, rel, params, step)[0]  # the fit at the last fix; its covariance
    P = ends.T @ cov @ ends  # carried linearly
    if not (np.all(np.isfinite(mode)) and np.all(np.isfinite(P))):
        return None
    return Refined(x, mode, 0.5 * (P + P.T), cost, it, logdet, converged, jac.shape[0] - n)
