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
Coefficients from measured flights: :func:`fit` and what it reports.

Every flight's release state and the freed shared values (:mod:`.coefficients`) are fitted at
once (:mod:`.problem`, :mod:`.solver`); unknown noise sigmas are estimated in turn with the fit
until they settle. When the spin is freed its hand is not known: both signs are tried and the
better fit kept. A flight without observed axes has its release rate held at zero unless
freeing those rates lowers the chi-square beyond chance (:mod:`.problem` says why). Each freed
value is then judged (:mod:`.uncertainty`): a value the data cannot determine is reported as
not identifiable, with the reason and no number; an identifiable one gets its 95 % interval
from the Jacobian, checked against the profile likelihood (the profile's where they differ).
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math

import numpy as np

from . import coefficients as co
from .problem import axis_frame, B_R, B_V, B_W, block_states, FitSettings, N_PRIOR, Problem
from .solver import FitError, minimise, Normal, profile_interval, State
from .track import Track
from .uncertainty import correlation, information, verdict, Z95
from ..physics.release import RPM

NOISE_ROUNDS = 6
"""Most refits for the estimated noise sigmas (each ends when they change by under 1 %)."""
RATE_SHOWN = 0.99
"""Chi-square quantile (2 degrees of freedom per flight) the fall of the chi-square from
freeing the held release rates must pass for an 'auto' fit to keep them freed."""


@dataclass(frozen=True)
class CoefficientFit:
    """
    One freed quantity as fitted.

    ``value`` and ``ci95`` (lo, hi) only if ``identifiable`` (else None
    and ``reason``); ``sigma`` its Jacobian 1-sigma (None without one); ``interval``
    'jacobian' or 'profile' (where the 95 % interval comes from).
    """

    name: str
    unit: str
    value: float | None
    ci95: tuple[float, float] | None
    sigma: float | None
    identifiable: bool
    reason: str
    interval: str | None


@dataclass(frozen=True)
class FlightFit:
    """
    One flight at the fit.

    ``name``, ``t0`` its first fix's time [s], ``times`` (K,) [s]
    since then, the ``fixes`` (K, 3) [m] and the ``fitted`` positions and axes (K, 6); the
    release state at the first fix (position [m], velocity [m/s], unit axis, transverse
    angular velocity [rad/s], spin [rpm], ``field``); whether that ``rate_fitted`` (else held
    at zero: :attr:`FitSettings.release_rate`); RMS position residual [m] and, with axis
    observations, RMS axis residual [deg].
    """

    name: str
    t0: float
    times: np.ndarray
    fixes: np.ndarray
    fitted: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    axis: np.ndarray
    transverse_rate: np.ndarray
    spin_rpm: float
    rate_fitted: bool
    residual_rms_m: float
    axis_residual_rms_deg: float | None


@dataclass(frozen=True)
class FitResult:
    """
    A fit's report.

    ``coefficients`` by name, their ``correlation`` (n, n) (NaN rows for those not
    identifiable), ``flights``, the RMS position residual [m] over all fixes, the position
    sigma [m] and axis sigma [deg] estimated (None where given), ``chi2`` and ``dof`` of the
    whitened residuals, Levenberg-Marquardt ``iterations`` and whether the fit ``converged``;
    ``model``, ``moment``, ``ball`` as fitted and ``fixed`` the values held (name -> value).
    """

    coefficients: dict[str, CoefficientFit]
    correlation: np.ndarray
    flights: list[FlightFit]
    residual_rms_m: float
    noise_m: float | None
    axis_noise_deg: float | None
    chi2: float
    dof: int
    iterations: int
    converged: bool
    model: str
    moment: str
    ball: str
    fixed: dict[str, float] = field(default_factory=dict)


def fit(tracks: list[Track], settings: FitSettings) -> FitResult:
    """
    Fit ``tracks`` (one or many flights) with ``settings`` (the module docstring).

    ValueError for bad settings (a coefficient the model lacks), FitError when a flight cannot
    be flown from its start.
    """
    if not tracks:
        raise ValueError('no flights to fit')
    problem = Problem(list(tracks), settings)
    start = co.start_values(problem.names, problem.ball, problem.aero, problem.spin_rpm)
    starts = [start]
    if 'spin_rpm' in problem.names:  # the hand is not known: try both
        starts.append(np.where(np.array(problem.names) == 'spin_rpm', -start, start))
    fits, failure = [], None
    for values in starts:
        try:
            state = _fit_noise(problem, problem.start(values), values, settings.max_iterations)
        except FitError as exc:
            failure = exc
            continue
        fits.append((state, problem.noise, problem.axis_sigma))
    if not fits:
        raise failure
    # Each start's cost is whitened by its own estimated sigmas: compare them under one.
    costs = [problem.cost(state.blocks, state.values) for state, _, _ in fits]
    state, problem.noise, problem.axis_sigma = fits[int(np.argmin(costs))]
    if problem.release_rate == 'auto' and not problem.rate_free.all():
        state = _free_shown_rates(problem, state, settings.max_iterations)
    return _report(problem, state, settings)


def _free_shown_rates(problem: Problem, state: State, max_iterations: int) -> State:
    """
    Free the held release rates if the positions show them ('auto'; :mod:`.problem`).

    They are freed and the fit redone under the same sigmas; they stay freed, and the fit is
    redone with the sigmas re-estimated, if the chi-square fell by more than its
    :data:`RATE_SHOWN` quantile for two degrees of freedom per freed flight. All or none: a
    wobble shows in a flight's drag, one flight's worth of it is within the noise.
    """
    from scipy.stats import chi2

    held = ~problem.rate_free
    problem.rate_free = np.ones_like(held)
    try:
        freed = minimise(problem, state.blocks, state.values, max_iterations=max_iterations)
    except FitError:
        freed = None
    if freed is None or state.cost - freed.cost <= chi2.ppf(RATE_SHOWN, 2 * held.sum()):
        problem.rate_free = ~held
        state.iterations += 0 if freed is None else freed.iterations
        return state
    refit = _fit_noise(problem, freed.blocks, freed.values, max_iterations)
    refit.iterations += state.iterations + freed.iterations
    return refit


def _fit_noise(problem: Problem, blocks: np.ndarray, values: np.ndarray,
               max_iterations: int) -> State:
    """Minimise, re-estimating the unknown noise sigmas until they settle."""
    state = minimise(problem, blocks, values, max_iterations=max_iterations)
    iterations = state.iterations
    for _ in range(NOISE_ROUNDS):
        fitted = state.blocks.size + state.values.size - problem.n_held
        if problem.estimate_noise(state.lin, fitted) < 0.01:
            break
        state = minimise(problem, state.blocks, state.values, max_iterations=max_iterations)
        iterations += state.iterations
    state.lin = problem.linearise(state.blocks, state.values)  # under the final sigmas
    state.cost, state.iterations = state.lin.cost, iterations
    return state


def _report(problem: Problem, state: State, settings: FitSettings) -> FitResult:
    normal = Normal.of(state.lin)
    marginal, moved = normal.marginal()
    inf = information(marginal, np.diag(normal.shared))
    names = list(problem.names)
    results = {}
    for j, name in enumerate(names):
        c = co.COEFFICIENTS[name]
        judged = verdict(inf, j, c.physical, names)
        sigma = judged.sigma if math.isfinite(judged.sigma) else None
        if not judged.identifiable:
            results[name] = CoefficientFit(name, c.unit, None, None, sigma, False,
                                           judged.reason, None)
            continue
        value = float(state.values[j])
        lo, hi, profiled = value - Z95 * sigma, value + Z95 * sigma, False
        if settings.profile:
            lo, hi, profiled = profile_interval(problem, state, j, sigma, inf.cov, moved)
        if hi - lo > c.physical[1] - c.physical[0]:
            results[name] = CoefficientFit(
                name, c.unit, None, None, sigma, False,
                f'its 95 % profile interval [{lo:.3g}, {hi:.3g}] is wider than its physical '
                f'range [{c.physical[0]:g}, {c.physical[1]:g}]', None)
            continue
        results[name] = CoefficientFit(name, c.unit, value, (float(lo), float(hi)), sigma, True,
                                       '', 'profile' if profiled else 'jacobian')
    corr = correlation(inf.cov)
    bad = [j for j, name in enumerate(names) if not results[name].identifiable]
    corr[bad, :] = np.nan
    corr[:, bad] = np.nan
    flights = [_flight(problem, state, f) for f in range(len(problem.tracks))]
    squares = sum(fl.residual_rms_m**2 * fl.times.size for fl in flights)
    fixed_names = tuple(
        n for n, c in co.COEFFICIENTS.items() if n not in names and settings.model in c.models
    )
    held = co.start_values(fixed_names, problem.ball, problem.aero, problem.spin_rpm)
    fixed = dict(zip(fixed_names, held.tolist()))
    return FitResult(
        results, corr, flights,
        float(math.sqrt(squares / sum(fl.times.size for fl in flights))),
        problem.noise if any(problem.pos_estimated) else None,
        math.degrees(problem.axis_sigma) if problem.axis_estimated else None,
        state.cost,
        problem.n_data + N_PRIOR * len(flights) - state.blocks.size - state.values.size,
        state.iterations, state.converged, settings.model, settings.moment,
        settings.ball.name, fixed)


def _flight(problem: Problem, state: State, f: int) -> FlightFit:
    """Flight ``f`` at the fit."""
    track, block = problem.tracks[f], state.blocks[f]
    spin = co.spin_of(problem.names, state.values[None], problem.spin_rpm)
    params = co.apply(problem.params, problem.names, state.values[None], problem.ball)
    out = problem.fly(f, block_states(block[None], spin, problem.ratio), params)[0]
    err = out[:, :3] - track.positions
    rows = problem.axis_rows[f]
    axis_rms = None
    if rows.size:
        cos = np.minimum(np.abs(np.sum(out[rows, 3:6] * track.axes[rows], axis=1)), 1.0)
        axis_rms = math.degrees(math.sqrt(np.mean(np.arccos(cos) ** 2)))
    s, e_psi, e_theta = (v[0] for v in axis_frame(block[6:7], block[7:8]))
    return FlightFit(
        track.name, float(track.times[0]), problem.rel[f], track.positions, out,
        block[B_R:B_R + 3].copy(), block[B_V:B_V + 3].copy(), s,
        block[B_W] * e_psi + block[B_W + 1] * e_theta, float(spin[0] / RPM),
        bool(problem.rate_free[f]),
        float(math.sqrt(np.mean(err**2))), axis_rms)
