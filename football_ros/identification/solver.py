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
Levenberg-Marquardt on the fit's block-arrow normal equations, and the profile likelihood.

Each flight's block of unknowns meets only its own residuals, the shared values meet all: the
information matrix J'J is block-arrow. Its per-flight blocks (N_BLOCK square, positive
definite: the fixes fix r and v, the wobble prior the rest) are eliminated (Schur complement),
leaving a system in the shared values alone, so that a step costs a few small solves per flight
and the marginal information of the shared values is that complement.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .problem import Linear, N_BLOCK, Problem
from .uncertainty import Z95

CONVERGED = 0.02
"""A Levenberg-Marquardt step that lowers the chi-square by less ends the fit."""
GEODESIC_H = 0.1
"""Finite-difference fraction of a step for the residuals' second derivative along it."""
ACCELERATION_RATIO = 0.75
"""Largest 2 |a| / |v| accepted (Transtrum and Sethna's)."""
PROFILE_TOLERANCE = 0.1
"""Accepted relative gap between the profile's and the Jacobian's interval end (in sigma)."""
PROFILE_ROUNDS = 4
"""Most refits per interval end (secant steps on the square root of the chi-square rise)."""
PROFILE_ITERATIONS = 4
"""Most Levenberg-Marquardt iterations of a refit (it starts on the linear prediction)."""
PROFILE_CONVERGED = 0.02
"""A refit with one value held ends at a smaller decrease than this."""


class FitError(ValueError):
    """The flights cannot be fitted (a flight that cannot be flown from the start values)."""


@dataclass(frozen=True)
class Normal:
    """
    The normal equations J'J and J'r in blocks.

    ``own`` (F, N_BLOCK, N_BLOCK), ``cross`` (F, N_BLOCK, n),
    ``shared`` (n, n); gradients ``g_own`` (F, N_BLOCK) and ``g_shared`` (n,).
    """

    own: np.ndarray
    cross: np.ndarray
    shared: np.ndarray
    g_own: np.ndarray
    g_shared: np.ndarray

    @classmethod
    def of(cls, lin: Linear) -> 'Normal':
        """Return the normal equations of a linearisation."""
        jb = [j[:, :N_BLOCK] for j in lin.jacobians]
        jc = [j[:, N_BLOCK:] for j in lin.jacobians]
        return cls(
            np.stack([b.T @ b for b in jb]),
            np.stack([b.T @ c for b, c in zip(jb, jc)]),
            sum(c.T @ c for c in jc),
            np.stack([b.T @ r for b, r in zip(jb, lin.residuals)]),
            sum(c.T @ r for c, r in zip(jc, lin.residuals)),
        )

    def step(
        self, lam: float, free: np.ndarray, gradient: tuple | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the damped Levenberg-Marquardt move: d_blocks (F, N_BLOCK), d_values (n,).

        -(J'J + lam D)^-1 g with D the floored diagonal, g = J'r or ``gradient`` (g_own,
        g_shared); the shared values where ``free`` is False held.
        """
        g_own, g_shared = gradient or (self.g_own, self.g_shared)
        own = self.own + lam * _diagonal(self.own)
        shared = self.shared + lam * np.diag(_floored(np.diag(self.shared)))
        cross = self.cross[:, :, free]
        rhs = np.concatenate([cross, g_own[:, :, None]], axis=2)
        solved = np.linalg.solve(own, rhs)  # own^-1 [cross, g_own]
        nf = int(free.sum())
        d_values = np.zeros(free.size)
        if nf:
            schur = shared[np.ix_(free, free)] - np.einsum('fic,fid->cd', cross, solved[:, :, :nf])
            grad = g_shared[free] - np.einsum('fic,fi->c', cross, solved[:, :, nf])
            d_values[free] = np.linalg.solve(schur, -grad)
        d_blocks = -(solved[:, :, nf] + np.einsum('fic,c->fi', solved[:, :, :nf],
                                                  d_values[free]))
        return d_blocks, d_values

    def scaled_norm(self, d_blocks: np.ndarray, d_values: np.ndarray) -> float:
        """Norm of a step in units of the information's diagonal (sqrt(sum D d^2))."""
        own = np.einsum('fii->fi', self.own)
        return math.sqrt(float(np.sum(own * d_blocks**2) + np.diag(self.shared) @ d_values**2))

    def marginal(self) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the shared values' marginal information (n, n) and own^-1 cross.

        The first is the Schur complement; own^-1 cross (F, N_BLOCK, n) says how each
        flight's best block moves per unit of the shared values.
        """
        moved = np.linalg.solve(self.own, self.cross)
        return self.shared - np.einsum('fic,fid->cd', self.cross, moved), moved


def _floored(diag: np.ndarray) -> np.ndarray:
    return np.maximum(diag, 1e-12 * max(float(np.max(diag, initial=0.0)), 1e-300))


def _diagonal(blocks: np.ndarray) -> np.ndarray:
    """Diagonal matrices (F, N, N) of each block's floored diagonal."""
    diag = np.array([_floored(np.diag(b)) for b in blocks])
    return diag[:, :, None] * np.eye(blocks.shape[1])[None]


@dataclass
class State:
    """
    A point of the fit.

    ``blocks`` (F, N_BLOCK), ``values`` (n,), its chi-square ``cost`` and linearisation
    ``lin``; ``iterations`` taken and whether it ``converged``.
    """

    blocks: np.ndarray
    values: np.ndarray
    cost: float
    lin: Linear
    iterations: int = 0
    converged: bool = False


def minimise(
    problem: Problem,
    blocks: np.ndarray,
    values: np.ndarray,
    held: tuple[int, ...] = (),
    max_iterations: int = 60,
    converged: float = CONVERGED,
) -> State:
    """
    Minimise by Levenberg-Marquardt from ``blocks``, ``values``.

    The shared values at indices ``held`` are kept. Until a step lowers the chi-square by
    less than ``converged``, no step lowers it, or ``max_iterations`` Jacobians. FitError if
    a flight cannot be flown at the start.
    """
    lin = problem.linearise(blocks, values)
    if lin is None:
        raise FitError('a flight cannot be flown from the start values')
    state = State(blocks.copy(), values.copy(), lin.cost, lin)
    free = np.ones(values.size, bool)
    free[list(held)] = False
    lam = 1e-3
    while state.iterations < max_iterations:
        state.iterations += 1
        normal = Normal.of(state.lin)
        new = math.inf
        while lam < 1e12:
            try:
                trial = _accelerated_step(problem, state, normal, lam, free)
            except np.linalg.LinAlgError:
                trial = None
            if trial is not None:
                new = problem.cost(*trial)
                if new < state.cost:
                    break
            lam *= 4.0
        if not new < state.cost:  # no step lowers it: at the minimum
            state.converged = True
            break
        lin = problem.linearise(*trial)
        if lin is None:  # flown at the cost, not at the Jacobian's steps: stop here
            state.converged = True
            break
        decrease = state.cost - new
        state.blocks, state.values, state.cost, state.lin = trial[0], trial[1], new, lin
        lam = max(lam / 4.0, 1e-9)
        if decrease <= converged:
            state.converged = True
            break
    return state


def _accelerated_step(
    problem: Problem, state: State, normal: Normal, lam: float, free: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """
    Return the step v + a/2 with geodesic acceleration (Transtrum and Sethna 2012).

    a solves the
    damped system for the residuals' second derivative along v (a finite difference of one
    extra flight per track); None when |a| exceeds :data:`ACCELERATION_RATIO` |v| (the
    quadratic model does not hold that far: more damping).
    """
    v_b, v_v = normal.step(lam, free)
    moved = problem.evaluate((state.blocks + GEODESIC_H * v_b)[:, None, :],
                             (state.values + GEODESIC_H * v_v)[None])
    g_own, g_shared = np.zeros_like(normal.g_own), np.zeros_like(normal.g_shared)
    for f, (r, jac, rh) in enumerate(zip(state.lin.residuals, state.lin.jacobians, moved)):
        if not np.all(np.isfinite(rh)):
            return None
        rvv = 2.0 / GEODESIC_H * ((rh[0] - r) / GEODESIC_H - jac @ np.concatenate([v_b[f], v_v]))
        g_own[f] = jac[:, :N_BLOCK].T @ rvv
        g_shared += jac[:, N_BLOCK:].T @ rvv
    a_b, a_v = normal.step(lam, free, (g_own, g_shared))
    if 2.0 * normal.scaled_norm(a_b, a_v) > ACCELERATION_RATIO * normal.scaled_norm(v_b, v_v):
        return None
    return state.blocks + v_b + 0.5 * a_b, state.values + v_v + 0.5 * a_v


def profile_interval(
    problem: Problem, state: State, index: int, sigma: float, cov: np.ndarray,
    moved: np.ndarray,
) -> tuple[float, float, bool]:
    """
    Return the 95 % interval of shared value ``index`` and whether it is the profile's.

    Each end starts at 1.96 ``sigma`` (the Jacobian's) and is kept if the profile's chi-square
    rise there (the others refitted, started on the linear prediction from ``cov`` (n, n) and
    ``moved`` (F, N_BLOCK, n), :meth:`Normal.marginal`) is 1.96^2 within
    :data:`PROFILE_TOLERANCE` on the square-root scale; else moved by secant steps on that
    square root until it is.
    """
    centre = state.values[index]
    ends, profiled = [], False
    for side in (-1.0, 1.0):
        offset = side * Z95 * sigma
        seen = [(0.0, 0.0)]  # (offset, sqrt of the chi-square rise): the secant's points
        for _ in range(PROFILE_ROUNDS):
            shift = cov[:, index] / cov[index, index] * offset
            values = state.values + shift
            values[index] = centre + offset
            blocks = state.blocks - np.einsum('fic,c->fi', moved, shift)
            try:
                held = minimise(problem, blocks, values, (index,), PROFILE_ITERATIONS,
                                PROFILE_CONVERGED)
            except FitError:
                break
            rise = math.sqrt(max(held.cost - state.cost, 0.0))
            if abs(rise / Z95 - 1.0) <= PROFILE_TOLERANCE:
                break
            profiled = True
            seen.append((offset, rise))
            (o1, r1), (o2, r2) = seen[-2], seen[-1]
            if r2 > r1:
                offset = o2 + (Z95 - r2) * (o2 - o1) / (r2 - r1)
            else:  # flat or falling: the profile is wider than it looked
                offset = 2.0 * o2
        ends.append(centre + offset)
    return ends[0], ends[1], profiled
