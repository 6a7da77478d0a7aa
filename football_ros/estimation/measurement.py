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
What one fix measured, and how the tracker weighs it: the measurement models of the tracker.

A measurement is a value ``z`` (m,), its noise covariance ``R`` (m, m) and a function
:meth:`Measurement.predict` from ball positions (k, 3) [m] in ``field`` to what the sensor
would have reported (k, m). :class:`PositionFix` is a 3D position (a detector's triangulated
fix, m = 3, identity model); :class:`ProjectedFix` is anything else a function of the position
gives (a camera's pixels: m = 2, its projection). The filter's update
(:func:`unscented_update`) and the batch fit (:func:`whitened_residuals`) take either; both see
the fix's covariance, made wider along the ball's path by the stamp's jitter
(:func:`with_timing`). Pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from typing import Callable

import numpy as np

from .unscented import moments, sigma_points

MAX_SIGMA = 100.0
"""Largest standard deviation [m, or the sensor's unit] a covariance may claim."""
MIN_SIGMA = 1e-5
"""Smallest standard deviation a covariance may claim (its smallest eigenvalue's root)."""
TIMING_STEP = 1e-3
"""Time step [s] of the central difference that gives d(predict)/dt along the velocity."""


def check_covariance(cov, size: int, what: str = 'covariance') -> np.ndarray:
    """
    Return ``cov`` as a symmetric (size, size) float array, or raise ValueError naming ``what``.

    Finite, symmetric to 1e-6 relative, its eigenvalues in [MIN_SIGMA^2, MAX_SIGMA^2].
    """
    try:
        c = np.asarray(cov, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f'{what} must be numbers') from None
    if c.shape == (size * size,):
        c = c.reshape(size, size)
    if c.shape != (size, size):
        raise ValueError(f'{what} must be {size}x{size}, got shape {c.shape}')
    if not np.all(np.isfinite(c)):
        raise ValueError(f'{what} has non-finite entries')
    scale = max(float(np.max(np.abs(c))), 1e-300)
    if float(np.max(np.abs(c - c.T))) > 1e-6 * scale:
        raise ValueError(f'{what} is not symmetric')
    c = 0.5 * (c + c.T)
    eig = np.linalg.eigvalsh(c)
    if eig[0] < MIN_SIGMA**2 or eig[-1] > MAX_SIGMA**2:
        raise ValueError(
            f'{what} must be positive definite with sigmas in [{MIN_SIGMA:g}, {MAX_SIGMA:g}], '
            f'got eigenvalues {eig[0]:.3g} .. {eig[-1]:.3g}'
        )
    return c


@dataclass(frozen=True, eq=False)
class Measurement:
    """
    One fix's value ``z`` (m,) and noise covariance ``R`` (m, m) (use a subclass).

    Subclasses give :meth:`predict`; ``R`` is checked at construction (ValueError). ``source``
    (hashable, e.g. a camera's name; None: one unnamed sensor) tells whose clock stamped it:
    the tracker measures the stamps' jitter per source (several unsynchronised cameras
    interleave their stamps irregularly).
    """

    z: np.ndarray
    R: np.ndarray
    source: object = None

    def __post_init__(self) -> None:
        z = np.asarray(self.z, dtype=float).reshape(-1).copy()
        if not np.all(np.isfinite(z)):
            raise ValueError('measurement has non-finite values')
        object.__setattr__(self, 'z', z)
        object.__setattr__(self, 'R', check_covariance(self.R, z.size))

    @property
    def size(self) -> int:
        return self.z.size

    def predict(self, positions: np.ndarray) -> np.ndarray:
        """Return what the sensor reports (k, m) for ball positions (k, 3) [m] in ``field``."""
        raise NotImplementedError

    def position_guess(self) -> np.ndarray | None:
        """Return the ball's position (3,) [m] in ``field`` if this fix gives it, else None."""
        return None


@dataclass(frozen=True, eq=False)
class PositionFix(Measurement):
    """A position fix: ``z`` (3,) [m] in ``field``, ``R`` (3, 3) [m^2]."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.z.size != 3:
            raise ValueError(f'position must have 3 components, got {self.z.size}')

    def predict(self, positions: np.ndarray) -> np.ndarray:
        return np.asarray(positions, dtype=float)

    def position_guess(self) -> np.ndarray:
        return self.z


@dataclass(frozen=True, eq=False)
class ProjectedFix(Measurement):
    """
    Any measurement that is a function of the ball's position (a camera's pixels).

    ``project`` maps positions (k, 3) [m] in ``field`` to (k, m) in the units of ``z``; it
    must be smooth near the ball and return NaN where it is undefined (behind a camera).
    """

    project: Callable[[np.ndarray], np.ndarray] | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if not callable(self.project):
            raise ValueError('a projected fix needs a callable project')

    def predict(self, positions: np.ndarray) -> np.ndarray:
        out = np.asarray(self.project(np.asarray(positions, dtype=float)), dtype=float)
        return out.reshape(len(positions), self.size)


def position_fix(position, covariance=None, noise: float = 0.02) -> PositionFix:
    """Return a :class:`PositionFix` of ``position`` with ``covariance`` or noise^2 I."""
    cov = noise**2 * np.eye(3) if covariance is None else covariance
    return PositionFix(np.asarray(position, dtype=float), cov)


def with_timing(meas: Measurement, position, velocity, jitter: float) -> Measurement:
    """
    Return ``meas`` with the noise of a stamp off by ``jitter`` [s, 1 sigma] added.

    A stamp off by dt sees the ball where it is dt later: d = d(predict)/dt = J v, from a
    central difference at ``position`` [m] along ``velocity`` [m/s]; R + jitter^2 d d'.
    ``meas`` unchanged if the jitter is 0 or the difference is not finite.
    """
    if jitter <= 0.0:
        return meas
    r = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    ends = meas.predict(np.stack([r - TIMING_STEP * v, r + TIMING_STEP * v]))
    d = (ends[1] - ends[0]) / (2.0 * TIMING_STEP)
    if not np.all(np.isfinite(d)):
        return meas
    return replace(meas, R=meas.R + jitter**2 * np.outer(d, d))


@dataclass(frozen=True)
class Innovation:
    """An update's outcome: the new mean and covariance, d2 (squared Mahalanobis), log|S|."""

    x: np.ndarray
    P: np.ndarray
    d2: float
    logdet: float


def unscented_update(x: np.ndarray, P: np.ndarray, meas: Measurement, spread: float):
    """
    Update (``x``, ``P``) (position first) with ``meas``; return an :class:`Innovation` or None.

    A position fix takes the exact Kalman update (Joseph form); any other measurement the
    unscented one (sigma points of spread ``spread`` through :meth:`Measurement.predict`),
    which is exact for a linear model. None if the innovation's covariance is singular or a
    number is not finite.
    """
    R = meas.R
    if isinstance(meas, PositionFix):
        zhat, S, Pxz = x[:3], P[:3, :3] + R, P[:, :3]
    else:
        pts, wm, wc = sigma_points(x, P, spread)
        images = meas.predict(pts[:, :3])
        if not np.all(np.isfinite(images)):
            return None
        zhat, Pzz = moments(images, wm, wc)
        S = Pzz + R
        Pxz = ((pts - x) * wc[:, None]).T @ (images - zhat)
    nu = meas.z - zhat
    try:
        d2 = float(nu @ np.linalg.solve(S, nu))
        logdet = float(np.linalg.slogdet(S)[1])
        K = np.linalg.solve(S, Pxz.T).T  # (n, m)
    except np.linalg.LinAlgError:
        return None
    xn = x + K @ nu
    if isinstance(meas, PositionFix):
        ikh = np.eye(x.size)
        ikh[:, :3] -= K
        Pn = ikh @ P @ ikh.T + K @ R @ K.T
    else:
        Pn = P - K @ S @ K.T
    Pn = 0.5 * (Pn + Pn.T)
    if not (math.isfinite(d2) and np.all(np.isfinite(xn)) and np.all(np.isfinite(Pn))):
        return None
    return Innovation(xn, Pn, d2, logdet)


class Whitener:
    """
    Whitened residuals of many fixes at once: L_k^-1 (predict_k(r_k) - z_k), R_k = L_k L_k'.

    Position fixes are done together (one einsum); any other fix one call each.
    """

    def __init__(self, fixes) -> None:
        self.fixes = list(fixes)
        self.pos = np.array(
            [k for k, f in enumerate(self.fixes) if isinstance(f, PositionFix)], dtype=int
        )
        self.other = [k for k, f in enumerate(self.fixes) if not isinstance(f, PositionFix)]
        self._z = np.array([self.fixes[k].z for k in self.pos]).reshape(-1, 3)
        R = np.array([self.fixes[k].R for k in self.pos]).reshape(-1, 3, 3)
        self._w = np.linalg.inv(np.linalg.cholesky(R))  # stacked: one call for all
        self._ow = [np.linalg.inv(np.linalg.cholesky(self.fixes[k].R)) for k in self.other]
        self.size = 3 * self.pos.size + sum(self.fixes[k].size for k in self.other)

    def __call__(self, positions: np.ndarray) -> np.ndarray:
        """Residuals (n, size) of positions (n, K, 3) [m] at the K fixes' times."""
        n = positions.shape[0]
        parts = [
            np.einsum('kij,nkj->nki', self._w, positions[:, self.pos] - self._z).reshape(n, -1)
        ]
        for k, w in zip(self.other, self._ow):
            fix = self.fixes[k]
            parts.append((fix.predict(positions[:, k]) - fix.z) @ w.T)
        return np.concatenate(parts, axis=1)
