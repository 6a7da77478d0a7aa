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
What a fit's information says of the shared values: covariance, correlation, identifiability.

The marginal information of the shared values (the Fisher matrix with every flight's release
state fitted too: :meth:`.solver.Normal.marginal`) is scaled to unit diagonal (correlation form)
and split by its eigenvalues: directions below :data:`NULL_RATIO` times the largest carry no
information (near-null). A value with a share above :data:`NULL_LOADING` in those directions,
or whose marginal information is below :data:`NULL_RATIO` times what it would have with the
release states known (the flights' own freedom mimics it), is not identifiable whatever its
interval; the others get the covariance of the pseudo-inverse over the informative directions
(exact for every value the null directions leave alone). A value whose 95 % interval is wider
than its physical range is not identifiable either: it is reported without a number.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

Z95 = 1.959963984540054
"""Two-sided 95 % normal quantile."""
NULL_RATIO = 1e-10
"""Eigenvalue of the unit-diagonal information matrix, relative to its largest, below which a
direction is near-null."""
NULL_LOADING = 0.01
"""Share of a parameter in the near-null directions above which it is not identifiable."""


@dataclass(frozen=True)
class Information:
    """
    The marginal information, split.

    ``cov`` (n, n) covariance (NaN rows for values with no information); ``loading`` (n,)
    each value's share in the near-null directions (1 for one the release states mimic);
    ``null`` (n, k) those directions (unit-diagonal scale); ``mimicked`` (n,) bool.
    """

    cov: np.ndarray
    loading: np.ndarray
    null: np.ndarray
    mimicked: np.ndarray


def information(marginal: np.ndarray, alone: np.ndarray) -> Information:
    """
    Split the marginal information ``marginal`` (n, n) of the shared values.

    ``alone`` (n,) is their information with the release states known (module docstring).
    """
    info = 0.5 * (marginal + marginal.T)
    diag = np.diag(info).copy()
    mimicked = ~(np.isfinite(diag) & (alone > 0.0) & (diag > NULL_RATIO * alone))
    d = np.where(mimicked, 1.0, np.sqrt(np.where(mimicked, 1.0, diag)))
    scaled = info / np.outer(d, d)
    scaled[mimicked, :] = 0.0
    scaled[:, mimicked] = 0.0
    w, vectors = np.linalg.eigh(scaled)
    null = w <= NULL_RATIO * max(float(w[-1]), 1e-300)
    loading = np.sum(vectors[:, null] ** 2, axis=1)
    loading[mimicked] = 1.0
    keep = vectors[:, ~null]
    cov = (keep / w[~null]) @ keep.T / np.outer(d, d)
    cov[mimicked, :] = np.nan
    cov[:, mimicked] = np.nan
    return Information(cov, loading, vectors[:, null], mimicked)


@dataclass(frozen=True)
class Verdict:
    """``sigma`` the 1-sigma of a parameter (NaN if unknown), whether identifiable, and why not."""

    sigma: float
    identifiable: bool
    reason: str


def verdict(
    inf: Information, index: int, physical: tuple[float, float], labels: list[str]
) -> Verdict:
    """
    Judge value ``index`` against its ``physical`` range (lo, hi).

    ``labels`` name the values (to say what a non-identifiable one is confounded with).
    """
    if inf.mimicked[index]:
        return Verdict(math.nan, False, "the flights' release states mimic it (no information "
                       'left once they are fitted)')
    if inf.loading[index] > NULL_LOADING:
        k = int(np.argmax(np.abs(inf.null[index, :])))
        vec = inf.null[:, k]
        partners = [labels[i] for i in np.argsort(-np.abs(vec))[:4]
                    if i != index and abs(vec[i]) > 0.2]
        reason = 'a near-null direction of the Fisher matrix'
        reason += f' (confounded with {", ".join(partners)})' if partners else ''
        return Verdict(math.nan, False, reason)
    sigma = float(math.sqrt(max(inf.cov[index, index], 0.0)))
    lo, hi = physical
    if not math.isfinite(sigma) or 2.0 * Z95 * sigma > hi - lo:
        return Verdict(
            sigma,
            False,
            f'its 95 % interval (+-{Z95 * sigma:.3g}) is wider than its physical range '
            f'[{lo:g}, {hi:g}]',
        )
    return Verdict(sigma, True, '')


def correlation(cov: np.ndarray) -> np.ndarray:
    """Correlation matrix of ``cov`` (NaN where a variance is not positive)."""
    s = np.sqrt(np.where(np.diag(cov) > 0.0, np.diag(cov), np.nan))
    out = cov / np.outer(s, s)
    np.fill_diagonal(out, np.where(np.isfinite(s), 1.0, np.nan))
    return out
