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


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """
    Return a x b over the last axis: np.cross's own products, bit for bit.

    Without its overhead (tens of microseconds a call), which was a quarter of a tumbling
    kick's multi-start fit (a call per residual row block, 3 per objective).
    """
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


def _basis(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors completing the unit ``u`` (continuous away from u = +/- z)."""
    a = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    b1 = _cross(a, u)
    b1 /= np.linalg.norm(b1)
    return b1, _cross(u, b1)


def _apply(x: np.ndarray, deltas: np.ndarray) -> np.ndarray:
    """States (m, n_x): ``x`` moved by each row of ``deltas`` (m, n_delta)."""
    n = deltas.shape[0]
    out = np.repeat(x[None, :], n, axis=0)
    out[:, X_R:X_R + 3] += deltas[:, 0:3]
    out[:, X_V:X_V + 3] += deltas[:, 3:6]
    b1, b2 = _basis(x[X_S:X_S + 3])
    s = x[X_S:X_S + 3] + deltas[:, 6:7] * b1 + deltas[:, 7:8] * b2
    out[:, X_S:X_S + 3] = s / np.linalg.norm(s, axis=1)[:, None]
    out[:, X_H:X_H + 3] += deltas[:, 8:11]
    out[:, X_KD] += deltas[:, 11]
    out[:, X_KL] += deltas[:, 12]
    if x.size >= N_X_WIND:
        out[:, X_W:X_W + 2] += deltas[:, 13:15]
    return out


def _prior_terms(states: np.ndarray, prior: Prior) -> np.ndarray:
    """Whitened prior residuals (m, 5 + len(prior.states)) of states at the first fix."""
    v = states[:, X_V:X_V + 3]
    s = states[:, X_S:X_S + 3]
    h = states[:, X_H:X_H + 3]
    vhat = v / np.linalg.norm(v, axis=1)[:, None]
    up = np.array([0.0, 0.0, 1.0])
    e2 = up - vhat[:, 2:3] * vhat
    e2 /= np.linalg.norm(e2, axis=1)[:, None]
    e3 = _cross(vhat, e2)
    h1 = np.einsum('ij,ij->i', h, s)
    perp = h - h1[:, None] * s
    b1, b2 = _basis(s[0])  # one transverse basis for all rows (they are near s[0])
    cols = [
        np.einsum('ij,ij->i', s, e2) / prior.axis_sigma,
        np.einsum('ij,ij->i', s, e3) / prior.axis_sigma,
        (h1 - prior.h1[0]) / prior.h1[1],
        perp @ b1 / prior.rate_sigma,
        perp @ b2 / prior.rate_sigma,
    ]
    cols += [(states[:, i] - mean) / sigma for i, mean, sigma in prior.states]
    return np.stack(cols, axis=1)


def _residuals(states, rel, whiten, params, step, prior):
    """Whitened residuals (m, n_fix + n_prior) of states at the first fix (end: at the last)."""
    first = states.copy()
    out = np.empty((states.shape[0], rel.size, 3))
    fly_through(states, rel, params, step, out)
    return np.concatenate([whiten(out), _prior_terms(first, prior)], axis=1)


def refine(
    times: np.ndarray,
    zs: np.ndarray,
    x0: np.ndarray,
    prior: Prior,
    noise: float,
    params: np.ndarray,
    step: float,
    max_iterations: int = 8,
) -> Refined | None:
    """
    Fit the throw to every fix (batch MAP) from ``x0``, the state at ``times[0]``.

    ``times`` (K,) [s] ascending; ``zs`` the fixes: (K, 3) positions [m] in ``field`` of
    1-sigma ``noise`` [m] per axis, or K :class:`~.measurement.Measurement` (each with its own
    covariance and model; ``noise`` unused); ``params`` the motion kernel's parameters,
    ``step`` [s] its longest RK4 step. Levenberg-Marquardt from ``x0`` until a step lowers the
    objective by less than :data:`CONVERGED`, no step lowers it, or ``max_iterations``
    Jacobians. At
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
    rel = times - times[0]
    n = 15 if x0.size >= N_X_WIND else 13
    steps = FD_STEP[:n]
    fd = np.vstack([np.zeros(n), np.diag(steps)])  # x, then x moved along each delta

    def linearise(x: np.ndarray):
        """(residuals at x, their Jacobian (m, n), d x(times[-1]) / d delta (n, n_x)) or None."""
        pts = _apply(x, fd)
        res = _residuals(pts, rel, whiten, params, step, prior)  # pts end at the last fix
        if not (np.all(np.isfinite(res)) and np.all(np.isfinite(pts))):
            return None
        return res[0], ((res[1:] - res[0]) / steps[:, None]).T, (pts[1:] - pts[0]) / steps[:, None]

    x = np.asarray(x0, dtype=float).copy()
    lin = linearise(x)
    if lin is None:
        return None
    lam, it, cost, converged = 1e-3, 0, math.inf, False
    while it < max_iterations:
        it += 1
        r0, jac = lin[:2]
        cost, g, info = float(r0 @ r0), jac.T @ r0, jac.T @ jac
        new, trial = math.inf, x
        while lam < 1e8:  # Levenberg-Marquardt: shorten the step until the objective falls
            try:
                d = np.linalg.solve(info + lam * np.diag(np.diag(info)), -g)
            except np.linalg.LinAlgError:
                return None
            trial = _apply(x, d[None, :])
            rt = _residuals(trial.copy(), rel, whiten, params, step, prior)[0]
            new = float(rt @ rt) if np.all(np.isfinite(rt)) else math.inf
            if new < cost:
                break
            lam *= 4.0
        if new >= cost:  # no step lowers it: at the minimum
            converged = True
            break
        x, lam, cost = trial[0], max(lam / 4.0, 1e-7), new
        if r0 @ r0 - new <= CONVERGED:  # the last Jacobian serves the posterior
            converged = True
            break
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
