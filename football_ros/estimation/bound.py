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
Information limit of a landing prediction: the Laplace (Gauss-Newton) posterior of a throw.

Fixes z_k = r(t_k; theta) + n_k, n_k ~ N(0, noise^2 I_3) independent, and a Gaussian prior of
information ``prior`` (a matrix, zero rows for a flat prior) on the throw's parameters theta.
Near the truth the posterior covariance is Sigma = (J' J / noise^2 + prior)^-1, J = d r / d
theta at the fixes, and the landing point's is C = G Sigma G', G = d (x, y)_landing / d theta:
the Bayesian Cramer-Rao bound of any predictor that uses these fixes and this prior, linearised
at the flight's true theta (exact for a linear model; no process noise, the model is the truth).
It holds for Gaussian priors; a bounded one (a uniform spin range) is stood in for by the
Gaussian of its variance. Whether an estimator reaches it is checked by fitting (see
bench/prediction_bound.py --map).

:class:`ThrowModel` maps theta (release position, speed, elevation, azimuth, axis offsets,
spin, drag and lift scales, optionally the axis rates) to the fixes and the landing with the
package's own flight (:class:`football_ros.physics.Flight`, full model), the same code that
makes the benchmark's true flights. Units: m, m/s, rad, rad/s; times [s] since the release.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable, Sequence

import numpy as np
from scipy import integrate, optimize

from ..physics.aero import AeroModel
from ..physics.flight import DEFAULT_STEP, Flight
from ..physics.presets import get_preset
from ..physics.release import initial_state_of, Release, release_states, RPM

THETA = (
    'x0', 'y0', 'z0', 'speed', 'elevation', 'azimuth', 'alpha0', 'beta0', 'spin', 'kd', 'kl'
)
"""Parameters of a throw [m, m, m, m/s, rad, rad, rad, rad, rad/s (signed), 1, 1]."""
THETA_RATES = THETA + ('alpha_rate', 'beta_rate')
"""With the axis rates at the release [rad/s] (as :class:`Release`'s, in rad/s)."""
THETA_WIND = ('wind_x', 'wind_y')
"""The horizontal wind [m/s] in ``field`` (the tracker's ``wind_sigma`` states), if unknown."""
FD_STEPS = {
    'x0': 1e-3, 'y0': 1e-3, 'z0': 1e-3, 'speed': 1e-3, 'elevation': 1e-5, 'azimuth': 1e-5,
    'alpha0': 1e-5, 'beta0': 1e-5, 'spin': 1e-2, 'kd': 1e-4, 'kl': 1e-4,
    'alpha_rate': 1e-4, 'beta_rate': 1e-4, 'wind_x': 1e-3, 'wind_y': 1e-3,
}
"""Central-difference steps per parameter (units of :data:`THETA`)."""
SQRT_2PI = math.sqrt(2.0 * math.pi)
QUARTILE = 0.6744897501960817
"""Upper quartile of the standard normal: the median of |X|."""


class ThrowModel:
    """
    Fixes and landing of a full-model throw as a function of its parameters theta.

    ``first`` [s] the first capture time after the release, then every ``period`` [s],
    ``count`` captures. ``aero`` the coefficients that kd = kl = 1 means (the tracker's
    nominal ones: kd multiplies C_D0 and C_D2, kl C_Lalpha, like
    :mod:`football_ros.estimation.tracker`); ``rates`` adds the axis rates to theta,
    ``wind`` the horizontal wind (:data:`THETA_WIND`; else the wind is ``aero``'s).
    """

    def __init__(
        self,
        first: float,
        period: float,
        count: int,
        ball: str = 'american',
        aero: AeroModel | None = None,
        rates: bool = False,
        step: float = DEFAULT_STEP,
        wind: bool = False,
        horizon: float = 20.0,
    ) -> None:
        if not (0.0 <= first and period > 0.0 and count >= 0):
            raise ValueError('first >= 0, period > 0 and count >= 0 are required')
        self.times = first + period * np.arange(count)
        self.ball = get_preset(ball)
        self.aero = aero or AeroModel()
        self.names = (THETA_RATES if rates else THETA) + (THETA_WIND if wind else ())
        self.step, self.horizon = step, horizon

    def theta_of(self, release: Release) -> np.ndarray:
        """Return the theta of a :class:`Release` (model 'full', same ball), in SI units."""
        a = release.aero_model()
        if a is None:
            raise ValueError("the release must use model 'full'")
        kd = a.c_d0 / self.aero.c_d0
        if not math.isclose(a.c_d2, kd * self.aero.c_d2, rel_tol=1e-9):
            raise ValueError('the release scales C_D0 and C_D2 differently: not one drag scale')
        kl = a.c_l_alpha / self.aero.c_l_alpha
        values = {
            'x0': release.position[0], 'y0': release.position[1], 'z0': release.position[2],
            'speed': release.speed, 'elevation': math.radians(release.elevation_deg),
            'azimuth': math.radians(release.azimuth_deg),
            'alpha0': math.radians(release.alpha0_deg), 'beta0': math.radians(release.beta0_deg),
            'spin': release.spin_rpm * RPM, 'kd': kd, 'kl': kl,
            'alpha_rate': math.radians(release.alpha_rate_deg_s),
            'beta_rate': math.radians(release.beta_rate_deg_s),
            'wind_x': a.wind[0], 'wind_y': a.wind[1],
        }
        return np.array([values[n] for n in self.names], dtype=float)

    def flight(self, theta: np.ndarray) -> Flight:
        """Return the :class:`Flight` (full model) that theta starts."""
        p = dict(zip(self.names, np.asarray(theta, dtype=float)))
        st = release_states(
            p['speed'], math.degrees(p['elevation']), math.degrees(p['azimuth']),
            p['spin'] / RPM, math.degrees(p['alpha0']), math.degrees(p['beta0']),
            math.degrees(p.get('alpha_rate', 0.0)), math.degrees(p.get('beta_rate', 0.0)),
            np.array([p['x0'], p['y0'], p['z0']]),
        )
        initial = initial_state_of(st)
        aero = dataclasses.replace(
            self.aero,
            c_d0=self.aero.c_d0 * p['kd'],
            c_d2=self.aero.c_d2 * p['kd'],
            c_l_alpha=self.aero.c_l_alpha * p['kl'],
            wind=(
                p.get('wind_x', self.aero.wind[0]),
                p.get('wind_y', self.aero.wind[1]),
                self.aero.wind[2],
            ),
        )
        return Flight(self.ball, initial, 'full', 'linear', self.step, aero)

    def fixes(self, theta: np.ndarray, flight: Flight | None = None) -> np.ndarray:
        """Return the fixes' true positions (3 count,), x, y, z of each capture [m]."""
        flight = flight or self.flight(theta)
        return np.array([flight.state_at(t)[:3] for t in self.times]).reshape(-1)

    def evaluate(self, theta: np.ndarray) -> np.ndarray:
        """
        Return the fixes' true positions and the landing, flattened.

        (3 count + 3,): x, y, z of each capture [m], then the landing's x, y [m] and time [s]
        (NaN if it does not land within ``horizon``).
        """
        flight = self.flight(theta)
        fixes = self.fixes(theta, flight)
        traj = flight.simulate(rate=100.0, duration=self.horizon)
        if not traj.landed:
            return np.concatenate([fixes, np.full(3, np.nan)])
        return np.concatenate([fixes, traj.positions[-1, :2], traj.times[-1:]])


def central_jacobian(
    fun: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, steps: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Return fun(theta) and its Jacobian (m, n) by central differences with ``steps`` (n,)."""
    theta = np.asarray(theta, dtype=float)
    f0 = np.asarray(fun(theta), dtype=float)
    jac = np.empty((f0.size, theta.size))
    for i, h in enumerate(steps):
        up, down = theta.copy(), theta.copy()
        up[i] += h
        down[i] -= h
        jac[:, i] = (np.asarray(fun(up)) - np.asarray(fun(down))) / (2.0 * h)
    return f0, jac


def posterior_covariance(jac: np.ndarray, noise: float, prior: np.ndarray) -> np.ndarray:
    """
    Return (J' J / noise^2 + prior)^-1.

    ``jac`` (m, n) of the measurements (each with 1-sigma ``noise``), ``prior`` (n, n)
    information. Solved in the scaling that makes the information's diagonal one (parameters
    of very different units).
    """
    info = jac.T @ jac / noise**2 + prior
    d = np.sqrt(np.diag(info))
    if np.any(d <= 0.0) or not np.all(np.isfinite(d)):
        raise np.linalg.LinAlgError('a parameter has no information (flat prior, no data)')
    scaled = info / np.outer(d, d)
    inv = np.linalg.inv(0.5 * (scaled + scaled.T))
    return inv / np.outer(d, d)


def radial_median(cov: np.ndarray) -> float:
    """
    Return the median of |e| [m] for e ~ N(0, cov), cov (2, 2).

    Exact: P(l1 X^2 + l2 Y^2 <= m^2) = 1/2 with X, Y standard normal, by quadrature.
    """
    lam = np.clip(np.linalg.eigvalsh(0.5 * (cov + cov.T)), 0.0, None)
    l2, l1 = float(lam[0]), float(lam[1])  # l1 >= l2
    if l1 <= 0.0:
        return 0.0
    if l2 <= 1e-14 * l1:
        return math.sqrt(l1) * QUARTILE

    def cdf(m: float) -> float:
        a = m / math.sqrt(l1)

        def inner(x: float) -> float:  # density of X times P(|Y| <= sqrt((m^2 - l1 x^2) / l2))
            rest = max(m * m - l1 * x * x, 0.0)
            return math.exp(-0.5 * x * x) / SQRT_2PI * math.erf(math.sqrt(rest / (2.0 * l2)))

        return integrate.quad(inner, -a, a, epsabs=1e-12, epsrel=1e-10)[0]

    lo = math.sqrt(l2) * math.sqrt(2.0 * math.log(2.0)) * 0.999  # isotropic at l2: below
    hi = math.sqrt(l1) * math.sqrt(2.0 * math.log(2.0)) * 1.001  # isotropic at l1: above
    return optimize.brentq(lambda m: cdf(m) - 0.5, lo, hi, xtol=1e-12 * hi)


def pooled_medians(covs: np.ndarray, draws: int = 2000, seed: int = 0) -> np.ndarray:
    """
    Return (draws,) medians over flights of |e_i|, one e_i ~ N(0, covs[i]) per flight.

    ``covs`` (n, 2, 2): what a benchmark of these n flights would report as the median error
    of an estimator at the bound, once per noise draw.
    """
    return mixture_pooled_medians([mixture_error([1.0], np.zeros((1, 2)), [c]) for c in covs],
                                  draws, seed)


def mixture_error(weights, means, covs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the error of a Gaussian mixture's mean under the mixture: (weights, offsets, covs).

    ``weights`` (k,) any scale, ``means`` (k, 2) [m], ``covs`` (k, 2, 2): the mixture
    sum_i w_i N(mean_i, cov_i) of the landing. Its mean m = sum_i w_i mean_i is the estimate
    of least mean square error under it, and m's error is the mixture sum_i w_i N(mean_i - m,
    cov_i): returned as the normalised weights, the offsets mean_i - m and the covs. One
    component: (1, 0, cov).
    """
    w = np.asarray(weights, dtype=float)
    w = w / w.sum()
    means = np.asarray(means, dtype=float).reshape(-1, 2)
    offsets = means - w @ means
    if w.size == 1:
        offsets = np.zeros((1, 2))
    return w, offsets, np.asarray(covs, dtype=float).reshape(-1, 2, 2)


def mixture_radial_median(error, samples: int = 20000, seed: int = 0) -> float:
    """
    Return the median of |e| [m] for e under the mixture ``error`` (:func:`mixture_error`).

    One component without offset: :func:`radial_median` (exact); else by ``samples`` draws.
    """
    w, offsets, covs = error
    if w.size == 1:
        return radial_median(covs[0])
    rng = np.random.default_rng(seed)
    pick = rng.choice(w.size, size=samples, p=w)
    chol = np.array([np.linalg.cholesky(c + 1e-18 * np.eye(2)) for c in covs])
    z = rng.standard_normal((samples, 2))
    e = np.einsum('sij,sj->si', chol[pick], z) + offsets[pick]
    return float(np.median(np.linalg.norm(e, axis=1)))


def mixture_pooled_medians(errors: list, draws: int = 2000, seed: int = 0) -> np.ndarray:
    """
    Return (draws,) medians over flights of |e_i|, one e_i per flight from ``errors[i]``.

    ``errors``: per flight the mixture of :func:`mixture_error`. The draws of the standard
    normals come first, so flights of one component without offset draw what
    :func:`pooled_medians` draws for their covs (the component picks come after).
    """
    rng = np.random.default_rng(seed)
    n = len(errors)
    z = rng.standard_normal((draws, n, 2))
    u = rng.random((draws, n))
    e = np.empty((draws, n, 2))
    for f, (w, offsets, covs) in enumerate(errors):
        chol = np.array([np.linalg.cholesky(c + 1e-18 * np.eye(2)) for c in covs])
        pick = np.minimum(np.searchsorted(np.cumsum(w), u[:, f]), w.size - 1)
        e[:, f] = np.einsum('dij,dj->di', chol[pick], z[:, f]) + offsets[pick]
    return np.median(np.linalg.norm(e, axis=-1), axis=1)


def pooled_median(covs: np.ndarray, draws: int = 2000, seed: int = 0) -> tuple[float, float]:
    """Return the mean and standard deviation of :func:`pooled_medians` over the draws."""
    med = pooled_medians(covs, draws, seed)
    return float(med.mean()), float(med.std())
