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

"""The unscented transform of the tracker and its batch refinement (scaled points, beta = 2)."""

import math

import numpy as np


def sigma_points(x: np.ndarray, P: np.ndarray, spread: float):
    """
    Return scaled unscented points (2n + 1, n) and the weights of mean and covariance.

    Row 0 is the mean, then x +/- spread sqrt(n) columns of chol(P); weights with beta = 2.
    """
    n = x.size
    try:
        L = np.linalg.cholesky(P)
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(0.5 * (P + P.T))
        L = v * np.sqrt(np.clip(w, 1e-12, None))
    scale = spread * math.sqrt(n)
    pts = np.empty((2 * n + 1, n))
    pts[0] = x
    pts[1:n + 1] = x + scale * L.T
    pts[n + 1:] = x - scale * L.T
    wm = np.full(2 * n + 1, 1.0 / (2.0 * spread**2 * n))
    wm[0] = 1.0 - 1.0 / spread**2
    wc = wm.copy()
    wc[0] += 3.0 - spread**2
    return pts, wm, wc


def moments(vals: np.ndarray, wm: np.ndarray, wc: np.ndarray):
    """Weighted mean and covariance of sigma-point images ``vals`` (2n + 1, m)."""
    mean = wm @ vals
    dev = vals - mean
    cov = (dev * wc[:, None]).T @ dev
    return mean, 0.5 * (cov + cov.T)
