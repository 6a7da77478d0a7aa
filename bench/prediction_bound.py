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
Information limit of the landing prediction on the prediction benchmark's own flights (headless).

For each flight of bench/prediction_benchmark.py (any of its cases: same generator, seeds,
ball, camera phase, rate and noise, 20 ms latency), the fixes delivered by ``lead`` s before
the true landing (as run_flight delivers them) give a Bayesian Cramer-Rao bound (the Laplace /
Gauss-Newton posterior at the true throw, football_ros.estimation.bound) of the landing point
(x, y on z = 0). Unknowns: the release position, speed, elevation, azimuth (flat priors), the axis
offsets alpha0, beta0, the spin, the drag and lift scales kd, kl; the release instant and the
hand are taken as known (both favour the bound). Priors:
- benchmark: the benchmark's own distribution: alpha0, beta0 ~ N(0, 1.5 deg), axis rates 0
  (known), |spin| uniform over the case's range (a Gaussian of its variance: sigma 115 rpm
  for 400-800 rpm); kd, kl sigma 0.3 (the truth is 1, or 1.3 / 0.7 in the 30 %-off cases);
- tracker: the tracker's own prior widths instead (TrackerSettings' axis_sigma, spin_sigma and
  scale_sigma; one Gaussian for the spin);
each with the spin known, the coefficients known (sigma -> 0) and both known, and a few
sensitivity rows (narrower priors, release point known, axis offsets known).
Per flight, the 2x2 covariance C gives the median of |e| under N(0, C) (exact); per set, the
median of these over flights ("med(med)"), and the median over flights of one draw per flight
("pooled": what a benchmark of these flights reports for an estimator at the bound; mean +/- sd
over draws), overall and by flight time (< 2.2 / 2.2-2.8 / > 2.8 s), and the probability that
the pooled median is <= 5 cm (the issue's target).
``--map`` fits the throw to the same fixes (batch MAP, Gauss-Newton, benchmark prior; hand
known): an estimator that reaches the bound shows that the bound is tight. ``--tracker``
replays the same fixes into the tracker (told nothing / the spin / the coefficients / both, as
the benchmark's oracle, and told nothing without its batch fit, 'filter alone'; ``--set``
changes TrackerSettings: NAME=VALUE, VALUE an int, a float or true / false, e.g.
``--set unstable_fits=false``) and prints its median error and the median over flights of
its error over the bound's per-flight median (1 = at the limit; with ``--modes`` over the
global bound's too), its landing NEES (mean) and the share inside the 95 % ellipse, its |spin|
error and how often it picked the right hand; ``--tracker-rows`` replays only some variants,
``--compare`` adds one told nothing with further changes on top of ``--set``'s.

The bound above is local: the posterior linearised at the true throw. Where the posterior
over theta has several modes that explain the fixes about equally well (a tumbling kick's
other spin, hand or tumble), it is optimistic: no estimator knows which mode is the truth's,
and none can reach it. ``--modes`` finds the modes on the same fixes (:func:`find_modes`:
batch MAP fits from the benchmark prior's starts, both hands, as the tracker's multi-start)
and prints, per flight, their objectives and evidence against the truth's own mode and
their landings' distance from it, and the global bound (:func:`global_error`): the
posterior as the Laplace mixture over the modes, each weighted by its evidence exp(-cost /
2) det(Sigma)^(1/2) (cost: chi-square of the fixes plus the prior's terms, so the prior's
density is in it; Sigma the Gauss-Newton posterior at the mode), the truth's own mode with
the local bound's covariance. The mixture's mean is the estimate of least mean square
error under that posterior; its error under the mixture, averaged over the flights the
prior draws, is the least any estimator can reach on average under that prior (the Bayes
risk: given the fixes, E|x - a|^2 = E|x - m|^2 + |m - a|^2 for any a). Its median (per
flight, exact for one mode; pooled over flights as the local bound's, the same draws) is
reported beside the local bound's. With one mode it is the local bound, draw for draw. It
assumes: each mode Gaussian (Laplace) and the modes found are all that hold weight (a mode
no start reaches is missing: one off to the side of those found would widen it); the spin
prior the two hands' Gaussians (the uniform range's variance each, equal odds) and the axis
rates flat (the tracker's prior is symmetric; the benchmark's tumbles have one sign); the
release point and velocity started at the truth (the fixes hold them
tightly); the median of |e|, like the local bound's, is what a benchmark reports, the mean
square what the mixture's mean minimises.

    .venv/bin/python bench/prediction_bound.py [--flights 60] [--seed 1] [--lead 1.0]
        [--all-cases] [--map] [--modes] [--tracker [--set NAME=VALUE ...]
        [--tracker-rows ROW ...] [--compare NAME=VALUE ...]]
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import math
import os
import sys
import time

from football_ros.estimation import FlightTracker, TrackerSettings
from football_ros.estimation.bound import (
    central_jacobian,
    FD_STEPS,
    mixture_error,
    mixture_pooled_medians,
    mixture_radial_median,
    pooled_medians,
    posterior_covariance,
    QUARTILE,
    radial_median,
    ThrowModel,
)
from football_ros.estimation.motion import X_H, X_S
from football_ros.physics import Flight, get_preset
from football_ros.physics.aero import AeroModel
from football_ros.physics.release import RPM
import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
_benchmark = importlib.import_module('prediction_benchmark')  # its flights, camera and cases
CASES, LATENCY, NOISE, RATE = (_benchmark.CASES, _benchmark.LATENCY, _benchmark.NOISE,
                               _benchmark.RATE)
random_releases = _benchmark.random_releases

CHI2_2_95 = 5.991
"""Chi-square 2 dof, 95 %: a landing inside the 95 % ellipse."""
CLASSES = (('< 2.2 s', 0.0, 2.2), ('2.2-2.8 s', 2.2, 2.8), ('> 2.8 s', 2.8, math.inf))
PRIOR_NAMES = ('benchmark', 'tracker')


def priors(case) -> dict:
    """
    Return {prior name: (axis offset sigma [rad], spin sigma [rad/s], scale sigma)} of a case.

    'benchmark': the case's own draws (|spin| uniform over its range: sigma range / sqrt(12));
    'tracker': the tracker's TrackerSettings for the case's ball.
    """
    tracker = TrackerSettings(ball=case.ball)
    return {
        'benchmark': (math.radians(1.5), (case.spin[1] - case.spin[0]) / math.sqrt(12.0) * RPM,
                      0.3),
        'tracker': (tracker.axis_sigma,
                    tracker.spin_sigma * get_preset(case.ball).spin_rpm * RPM,
                    tracker.scale_sigma),
    }


KNOWN = {
    'neither known': (),
    'spin known': ('spin',),
    'coefs known': ('kd', 'kl'),
    'both known': ('spin', 'kd', 'kl'),
}
TRACKER_ROWS = ('neither known', 'spin known', 'coefs known', 'both known', 'filter alone')
COMPARED = 'neither known, compared'
"""The tracker row told nothing with ``--compare``'s changes on top of ``--set``'s."""
BOUND_ROW = {'filter alone': 'neither known', COMPARED: 'neither known'}
"""The bound row a tracker row is held against, where they are not named alike."""


def camera_fixes(release, seed: int, t_land: float, lead: float, case) -> list:
    """Return the case camera's fixes of a flight delivered by ``lead`` s before landing."""
    fixes = _benchmark.camera_fixes(release, seed, t_land, case)
    return [o for o in fixes if o.delivery <= t_land - lead]


def field_setup(release, seed: int, lead: float, case):
    """
    :func:`flight_setup` of a field case (the benchmark's ``field_fixes``; no gust).

    The model's times are the true capture times (the jittered stamps are what the tracker
    sees); each fix's covariance, noise^2 diag(1, depth^2, 1) + jitter^2 v v' (v the true
    velocity), is in the model's ``whiten`` (K, 3, 3): L^-1 with R = L L'.
    """
    fixes, t_land, xy_land, drawn = _benchmark.field_fixes(release, seed, case)
    kept = [(o, c) for o, c in fixes if o.delivery <= t_land - lead]
    obs = [o for o, _ in kept]
    model = ThrowModel(obs[0].delivery - LATENCY, 1.0 / drawn['rate'], len(obs), ball=case.ball,
                       aero=AeroModel(wind=release.aero_model().wind),
                       rates=case.tumble is not None)
    if not np.allclose(model.times, [o.delivery - LATENCY for o in obs], atol=1e-9, rtol=0.0):
        raise RuntimeError('the captures are not on one grid')
    flight = Flight.from_release(release)
    whiten = []
    for t in model.times:
        v = flight.state_at(float(t))[3:6]
        R = case.noise**2 * np.diag([1.0, drawn['depth'] ** 2, 1.0])
        R = R + drawn['jitter'] ** 2 * np.outer(v, v)
        whiten.append(np.linalg.inv(np.linalg.cholesky(R)))
    model.whiten, model.noise_unit = np.array(whiten), case.noise
    model.told = [c for _, c in kept]
    return t_land, xy_land, obs, model


def flight_setup(release, seed: int, lead: float, case, wind_sigma: float = 0.0):
    """
    Return (t_land, xy_land, the fixes (:func:`camera_fixes`), their model).

    With ``wind_sigma`` > 0 the horizontal wind is among the model's unknowns (the tracker's
    wind states); else the model flies in the flight's true wind (known). A field case's
    fixes and model come from :func:`field_setup`.
    """
    if any(case is c for c in _benchmark.FIELD_CASES.values()):
        return field_setup(release, seed, lead, case)
    truth = Flight.from_release(release).simulate(rate=100.0, duration=20.0)
    t_land = float(truth.times[-1])
    obs = camera_fixes(release, seed, t_land, lead, case)
    aero = AeroModel() if wind_sigma > 0.0 else AeroModel(wind=release.aero_model().wind)
    model = ThrowModel(obs[0].stamp, 1.0 / case.rate, len(obs), ball=case.ball, aero=aero,
                       wind=wind_sigma > 0.0)
    if not np.allclose(model.times, [o.stamp for o in obs], rtol=0.0, atol=1e-9):
        raise RuntimeError(f'the fixes are not on one {case.rate:g} Hz grid')
    return t_land, truth.positions[-1, :2], obs, model


def jacobians(release, model: ThrowModel, xy_land) -> dict:
    """Return theta's names and the Jacobians of the fixes (3 count, n) and landing (2, n)."""
    jac = jacobians_at(model, model.theta_of(release))
    if np.linalg.norm(jac['xy'] - xy_land) > 1e-6:
        raise RuntimeError(f'the model misses the true landing by {jac["xy"] - xy_land}')
    return jac


def jacobians_at(model: ThrowModel, theta: np.ndarray) -> dict:
    """
    Return :func:`jacobians` at ``theta``, and its landing 'xy' [m] (NaN if it does not land).

    The fixes' rows whitened by each fix's covariance where the model has one (a field case),
    scaled back by the noise :func:`posterior` takes.
    """
    count = model.times.size
    steps = [FD_STEPS[n] for n in model.names]
    f0, jac = central_jacobian(model.evaluate, theta, steps)
    fixes = jac[: 3 * count]
    whiten = getattr(model, 'whiten', None)
    if whiten is not None:  # each fix's own covariance, scaled by the noise posterior() takes
        fixes = np.einsum('kab,kbn->kan', whiten, fixes.reshape(count, 3, -1))
        fixes = fixes.reshape(3 * count, -1) * model.noise_unit
    return {'names': model.names, 'fixes': fixes, 'landing': jac[3 * count: 3 * count + 2],
            'xy': f0[-3:-1]}


def posterior(jac: dict, sigmas: dict, noise: float) -> tuple[np.ndarray, np.ndarray, list]:
    """
    Return the landing covariance (2, 2), the parameters' and their names.

    ``sigmas``: prior sigma per parameter name (0 = known, absent = flat); ``noise`` [m] of
    the fixes.
    """
    names = [n for n in jac['names'] if sigmas.get(n, math.inf) > 0.0]
    keep = [jac['names'].index(n) for n in names]
    prior = np.diag([1.0 / sigmas[n] ** 2 if n in sigmas else 0.0 for n in names])
    cov = posterior_covariance(jac['fixes'][:, keep], noise, prior)
    g = jac['landing'][:, keep]
    return g @ cov @ g.T, cov, names


WIND_SIGMA = [0.0]
"""The wind's prior sigma [m/s] of this run (``--wind-sigma``; 0: the wind is known)."""


def camera_bound(release, detections, case, prior: str = 'benchmark') -> np.ndarray:
    """
    Return the landing covariance (2, 2) of the bound from camera detections, in pixel space.

    ``detections``: (exposure time [s], :class:`football_ros.estimation.camera.Camera`,
    width [px], pixel noise [px]) of each inlier detection; each measures (u, v) with the
    camera's pixel noise and the apparent width w with the noise the tracker assumes
    (camera_fusion.width_sigma), through the camera model (no triangulation).
    """
    from football_ros.estimation.camera_fusion import width_sigma

    ball = get_preset(case.ball)
    model = ThrowModel(0.0, 1.0, 0, ball=case.ball, aero=AeroModel(wind=release.aero_model().wind))
    model.times = np.array([d[0] for d in detections])
    theta = model.theta_of(release)
    f0, jac = central_jacobian(model.evaluate, theta, [FD_STEPS[n] for n in model.names])
    count = model.times.size
    rows = []
    for k, (_t, camera, width, noise) in enumerate(detections):
        r = f0[3 * k: 3 * k + 3]
        uv, h_uv = camera.project(r)
        h_w = np.array([
            (camera.image_width(r + e, ball.diameter) - camera.image_width(r - e, ball.diameter))
            / 2e-4 for e in 1e-4 * np.eye(3)
        ])
        j_pos = jac[3 * k: 3 * k + 3]
        rows += [h_uv[0] @ j_pos / noise, h_uv[1] @ j_pos / noise,
                 h_w @ j_pos / width_sigma(camera, uv, width, noise)]
    sigmas = prior_sigmas(case, prior)
    names = [n for n in model.names if sigmas.get(n, math.inf) > 0.0]
    keep = [model.names.index(n) for n in names]
    info_prior = np.diag([1.0 / sigmas[n] ** 2 if n in sigmas else 0.0 for n in names])
    cov = posterior_covariance(np.array(rows)[:, keep], 1.0, info_prior)
    g = jac[3 * count: 3 * count + 2][:, keep]
    return g @ cov @ g.T


def prior_sigmas(case, prior: str, known=(), **changes) -> dict:
    """Prior sigma per parameter for a case's :func:`priors` entry, ``known`` ones at 0."""
    axis_s, spin_s, scale_s = priors(case)[prior]
    sig = {'alpha0': axis_s, 'beta0': axis_s, 'spin': spin_s, 'kd': scale_s, 'kl': scale_s}
    if WIND_SIGMA[0] > 0.0:
        sig.update(wind_x=WIND_SIGMA[0], wind_y=WIND_SIGMA[0])
    sig.update(changes)
    sig.update(dict.fromkeys(known, 0.0))
    return sig


def tracker_errors(release, obs: list, xy_land, case, changes: dict, told_covs=None,
                   rows=TRACKER_ROWS, compare: dict | None = None) -> dict:
    """
    Replay the fixes ``obs`` (:func:`camera_fixes`) into the tracker.

    Told nothing / the spin / the coefficients / both (the benchmark's oracle settings), with
    ``changes`` to every TrackerSettings; and told nothing without the batch fit ('filter
    alone': refine_iterations 0); ``told_covs`` each fix's covariance told (None: not); only
    the variants in ``rows``, and told nothing with ``compare`` on top of ``changes``
    (:data:`COMPARED`) if given. Per variant: (landing error [m], |spin| error [rpm], hand
    right, landing NEES (x, y)).
    """
    spin = {'spin_rpm': max(abs(release.spin_rpm), 10.0), 'spin_sigma': 0.01}
    coefs = {'scale_sigma': 0.01, 'aero': release.aero_model()}
    settings = {
        'neither known': {},
        'spin known': spin,
        'coefs known': coefs,
        'both known': {**spin, **coefs},
        'filter alone': {},  # told nothing, and no batch fit: the unscented filter's own
    }
    settings = {name: kw for name, kw in settings.items() if name in rows}
    if compare:
        settings[COMPARED] = compare
    told = {'noise': case.noise, 'ball': case.ball}  # as the benchmark tells it
    out = {}
    for name, kw in settings.items():
        alone = {'refine_iterations': 0} if name == 'filter alone' else {}
        tracker = FlightTracker(TrackerSettings(**{**told, **kw, **changes, **alone}))
        for k, o in enumerate(obs):
            tracker.update(o.stamp, o.position, covariance=told_covs[k] if told_covs else None)
        pred = tracker.predict_landing()
        est = tracker.estimate
        if pred is None or est is None:
            out[name] = (math.nan, math.nan, False, math.nan)
            continue
        x = est[1]
        h1 = float(x[X_H:X_H + 3] @ x[X_S:X_S + 3])
        spin_rpm = h1 / tracker.ball.inertia_ratio / RPM
        e = pred.position[:2] - xy_land
        out[name] = (
            float(np.linalg.norm(e)),
            abs(abs(spin_rpm) - abs(release.spin_rpm)),
            bool(np.sign(spin_rpm) == np.sign(release.spin_rpm)),
            float(e @ np.linalg.solve(pred.covariance[:2, :2], e)),
        )
    return out


def map_errors(release, obs: list, model: ThrowModel, xy_land, case) -> dict:
    """
    Landing error [m] of the batch MAP fit (Gauss-Newton, benchmark prior) on the fixes ``obs``.

    Per :data:`KNOWN` set: theta maximising the posterior (least squares of the fixes and
    the prior), started at the prior mean for the axis offsets, spin (right hand) and scales
    and at the truth for the release point and velocity (the fixes hold them tightly); the
    landing of that theta. Achieving the bound tells that it is tight (the linearisation holds).
    """
    z = np.concatenate([o.position for o in obs])
    truth = model.theta_of(release)
    mean = {'alpha0': 0.0, 'beta0': 0.0, 'kd': 1.0, 'kl': 1.0,
            'spin': math.copysign(0.5 * (case.spin[0] + case.spin[1]) * RPM, release.spin_rpm)}
    out = {}
    for kname, known in KNOWN.items():
        sig = prior_sigmas(case, 'benchmark', known)
        free = [i for i, n in enumerate(model.names) if sig.get(n, math.inf) > 0.0]
        mu = np.array([mean.get(model.names[i], 0.0) for i in free])
        w = np.array([1.0 / sig[model.names[i]] if model.names[i] in sig else 0.0 for i in free])

        def full(xf, free=free):
            th = truth.copy()
            th[free] = xf
            return th

        def resid(xf, full=full, mu=mu, w=w):
            f = model.evaluate(full(xf))
            return np.concatenate([(f[: z.size] - z) / case.noise, w * (xf - mu)])

        steps = [FD_STEPS[model.names[i]] for i in free]
        x0 = np.where(w > 0.0, mu, truth[free])
        fit = least_squares(resid, x0, jac=lambda xf: central_jacobian(resid, xf, steps)[1],
                            method='lm', x_scale='jac')
        land = model.evaluate(full(fit.x))[-3:-1]
        out[kname] = float(np.linalg.norm(land - xy_land))
    return out


MODE_SAME = 25.0
"""Two fits of one flight and hand are one mode within this Mahalanobis distance^2 of theta
(under the posterior of the lower objective's)."""
MODE_WEIGHT = 1e-9
"""A mode of less evidence (normalised) is left out of the global bound's mixture."""


@dataclasses.dataclass
class Mode:
    """
    One mode of a flight's posterior over theta: the batch MAP fit from one start.

    ``hand`` +1 / -1: the spin prior's component it was fitted under; ``cost`` the objective
    (chi-square of the fixes plus the prior's terms); ``evidence`` its log Laplace evidence,
    -cost / 2 + log det(Sigma) / 2 (the same constant for every mode of a flight: the hands'
    prior components have equal odds and one normalisation); ``xy`` its landing [m], ``cov``
    the landing's Laplace covariance at the mode (2, 2); ``d2`` the truth's Mahalanobis
    distance^2 from it (under its posterior).
    """

    theta: np.ndarray
    hand: float
    cost: float
    evidence: float
    xy: np.ndarray
    cov: np.ndarray
    d2: float


def mode_starts(truth: np.ndarray, names: tuple, case) -> list:
    """
    Return [(hand, theta)]: the multi-start fit's starts, drawn from the benchmark's prior.

    As the tracker's (:meth:`FlightTracker._prior_starts`): the release point and velocity
    at the truth (the fixes hold them tightly; flat priors), the axis offsets and scales at
    their prior means, for each hand the spin at the middle of each third of the case's range
    (the middle alone with the axis rates unknown), and with the rates unknown, a tumble
    end over end either way at the low end, middle and high end of the case's range (none:
    20-120 rpm); and the truth itself (its hand), so that its own mode is among them.
    """
    at = {n: i for i, n in enumerate(names)}
    lo, hi = case.spin
    thirds = [lo + (i + 0.5) * (hi - lo) / 3.0 for i in range(3)]
    spins = [0.5 * (lo + hi)] if 'alpha_rate' in at else thirds
    tlo, thi = case.tumble or (20.0, 120.0)
    rates = ([6.0 * r * sign for r in (tlo, 0.5 * (tlo + thi), thi) for sign in (1.0, -1.0)]
             if 'alpha_rate' in at else [None])  # rev/min -> deg/s
    out = [(math.copysign(1.0, truth[at['spin']]), truth.copy())]
    for hand in (1.0, -1.0):
        for spin in spins:
            for rate in rates:
                th = truth.copy()
                th[at['alpha0']] = th[at['beta0']] = 0.0
                th[at['kd']] = th[at['kl']] = 1.0
                th[at['spin']] = hand * spin * RPM
                if rate is not None:
                    th[at['alpha_rate']], th[at['beta_rate']] = math.radians(rate), 0.0
                out.append((hand, th))
    return out


def find_modes(release, obs: list, model: ThrowModel, case) -> list:
    """
    Return the distinct modes (:class:`Mode`) of a flight's posterior, lowest objective first.

    The batch MAP fit (Levenberg-Marquardt, forward differences) of the fixes ``obs`` (each
    whitened by its covariance where the model has one, else by the case's noise) under the
    benchmark prior (:func:`prior_sigmas`, neither known; the spin's Gaussian centred on
    the start's hand: the prior is the two hands' mixture, equal odds), from each of
    :func:`mode_starts`. Fits of one hand within :data:`MODE_SAME` of a lower one are one
    mode; a fit that does not land is left out.
    """
    z = np.concatenate([o.position for o in obs])
    whiten = getattr(model, 'whiten', None)
    sig = prior_sigmas(case, 'benchmark')
    names = model.names
    w = np.array([1.0 / sig[n] if n in sig else 0.0 for n in names])
    steps = np.array([FD_STEPS[n] for n in names])
    mid = 0.5 * (case.spin[0] + case.spin[1]) * RPM
    truth = model.theta_of(release)

    def fixes_residuals(th):
        d = model.fixes(th) - z
        if whiten is None:
            return d / case.noise
        return np.einsum('kab,kb->ka', whiten, d.reshape(-1, 3)).reshape(-1)

    fits = []
    for hand, x0 in mode_starts(truth, names, case):
        mu = np.array([{'kd': 1.0, 'kl': 1.0, 'spin': hand * mid}.get(n, 0.0) for n in names])

        def resid(th, mu=mu):
            return np.concatenate([fixes_residuals(th), w * (th - mu)])

        def jac(th, resid=resid):
            r0 = resid(th)
            return np.stack([(resid(th + h * e) - r0) / h
                             for h, e in zip(steps, np.eye(th.size))], axis=1)

        try:
            fit = least_squares(resid, x0, jac=jac, method='lm', x_scale='jac', max_nfev=100)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if np.all(np.isfinite(fit.fun)):
            fits.append((float(fit.fun @ fit.fun), hand, fit.x, fit.jac))
    modes = []
    for cost, hand, theta, jac in sorted(fits, key=lambda f: f[0]):
        if any(m.hand == hand and float(np.sum((jl @ (theta - m.theta)) ** 2)) < MODE_SAME
               for m, jl in modes):
            continue
        at = jacobians_at(model, theta)
        if not np.all(np.isfinite(at['xy'])):
            continue
        c, cov, _ = posterior(at, sig, case.noise)
        logdet = float(np.linalg.slogdet(cov)[1])
        d2 = float(np.sum((jac @ (truth - theta)) ** 2))
        modes.append((Mode(theta, hand, cost, 0.5 * (logdet - cost), at['xy'], c, d2), jac))
    return [m for m, _ in modes]


def global_error(modes: list, local_cov: np.ndarray):
    """
    Return the global bound's error mixture of a flight (:func:`.bound.mixture_error`).

    The Laplace mixture over its ``modes``, each weighted by its evidence (those below
    :data:`MODE_WEIGHT` left out), the truth's own mode (least ``d2``) with the local bound's
    covariance ``local_cov`` (the posterior at the truth); so a flight of one mode has the
    local bound's error exactly (and one whose fits all failed).
    """
    if not modes:
        return mixture_error([1.0], np.zeros((1, 2)), [local_cov])
    ev = np.array([m.evidence for m in modes])
    wts = np.exp(ev - ev.max())
    wts /= wts.sum()
    own = int(np.argmin([m.d2 for m in modes]))
    keep = [i for i in range(len(modes)) if wts[i] >= MODE_WEIGHT or i == own]
    covs = [local_cov if i == own else modes[i].cov for i in keep]
    return mixture_error(wts[keep], [modes[i].xy for i in keep], covs)


def bound_cells(masks: list, meds: np.ndarray, pooled) -> str:
    """
    Return a bound row's cells: per class, med(med) and pooled mean +/- sd [cm].

    ``meds``: each flight's median error [m]; ``pooled(mask)``: the pooled medians over the
    draws (an array [m]) of the flights in ``mask``; '-' for a class without flights.
    """
    cells = ''
    for _, m in masks:
        if not m.any():
            cells += f'{"-":>26}'
            continue
        med = pooled(m)
        cells += (f'{np.median(meds[m]) * 100:>10.2f}{med.mean() * 100:>9.2f} '
                  f'+/-{med.std() * 100:>4.1f}')
    return cells


def global_rows(spec, jacs: list, modes: list, t_lands: np.ndarray, masks: list,
                draws: int, trk: list) -> np.ndarray:
    """
    Print the global bound beside the local one (benchmark prior, neither known), and the modes.

    Per flight: the modes of weight 1e-4 or more, or within 30 of chi-square of the truth's
    own mode (their hand, spin and tumble [rev/min], objective and -2 log evidence over the
    own mode's, landing distance from it [cm], weight), and the tracker's error [cm] and NEES
    per row of ``trk`` (:func:`tracker_errors`, if replayed). Returns the global bound's
    median per flight [m].
    """
    local = np.array([posterior(j, prior_sigmas(spec, 'benchmark'), spec.noise)[0] for j in jacs])
    errors = [global_error(md, c) for md, c in zip(modes, local)]
    gmeds = np.array([mixture_radial_median(e) for e in errors])
    cells = bound_cells(masks, gmeds, lambda m: mixture_pooled_medians(
        [e for e, keep in zip(errors, m) if keep], draws, seed=1))
    print(f'{"global bound (modes, Laplace mixture)":>40}{cells}')
    names = jacs[0]['names']
    spin_at = names.index('spin')
    rate_at = names.index('alpha_rate') if 'alpha_rate' in names else None
    print("modes per flight (the truth's own mode first; dchi2 and dev: objective and -2 log "
          'evidence over its; d: landing distance from it)')
    second = 0
    for i, (md, c, e) in enumerate(zip(modes, local, errors)):
        if not md:
            print(f'{i:>3} {t_lands[i]:.2f} s: no fit landed')
            continue
        own = min(md, key=lambda mo: mo.d2)
        ev = np.array([mo.evidence for mo in md])
        wts = np.exp(ev - ev.max())
        wts /= wts.sum()
        second += int(np.sum(wts >= 0.01) > 1)
        parts = []
        for mo, wt in sorted(zip(md, wts), key=lambda p: p[0] is not own):
            if wt < 1e-4 and mo.cost - own.cost > 30.0:
                continue
            tumble = (f'/{math.degrees(mo.theta[rate_at]) / 6.0:+.0f}' if rate_at is not None
                      else '')
            dev = 2.0 * (own.evidence - mo.evidence)
            parts.append(f'{mo.theta[spin_at] / RPM:+.0f}{tumble} rpm dchi2 '
                         f'{mo.cost - own.cost:+.1f} dev {dev:+.1f} '
                         f'd {np.linalg.norm(mo.xy - own.xy) * 100:.0f} w {wt:.3f}')
        replay = ''.join(f' [{name}: {t[0] * 100:.1f} cm, NEES {t[3]:.2f}]'
                         for name, t in (trk[i].items() if trk else ()))
        print(f'{i:>3} {t_lands[i]:.2f} s: local {radial_median(c) * 100:.1f} cm, global '
              f'{mixture_radial_median(e) * 100:.1f} cm;{replay} ' + '; '.join(parts))
    print(f'flights with a second mode of weight >= 0.01: {second}/{len(modes)}')
    return gmeds


def _value(text: str):
    """Parse a --set value: true / false (any case), else an int or a float."""
    if text.lower() in ('true', 'false'):
        return text.lower() == 'true'
    try:
        return int(text)
    except ValueError:
        return float(text)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument('--flights', type=int, default=60, help='flights per case')
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--lead', type=float, default=1.0, help='lead time before the landing [s]')
    ap.add_argument('--cases', nargs='*', default=['defaults'], help="the benchmark's cases")
    ap.add_argument('--all-cases', action='store_true', help="every case of the benchmark's")
    ap.add_argument('--tracker', action='store_true', help='replay the fixes into the tracker')
    ap.add_argument('--set', nargs='*', default=[], metavar='NAME=VALUE',
                    help='TrackerSettings changes for the replay, e.g. accel_noise=0')
    ap.add_argument('--tracker-rows', nargs='*', default=list(TRACKER_ROWS),
                    choices=TRACKER_ROWS, help='the tracker variants replayed')
    ap.add_argument('--compare', nargs='*', default=[], metavar='NAME=VALUE',
                    help="a tracker row told nothing with these changes on top of --set's")
    ap.add_argument('--map', action='store_true', help='batch MAP fit on the same fixes')
    ap.add_argument('--modes', action='store_true',
                    help="the posterior's modes on the same fixes and the global bound")
    ap.add_argument('--draws', type=int, default=4000)
    ap.add_argument('--seeds', type=int, default=1,
                    help="the flights of this many of the benchmark's draws (seeds seed..)")
    ap.add_argument('--wind-sigma', type=float, default=0.0,
                    help='the wind unknown with this prior sigma [m/s], the tracker told it too')
    args = ap.parse_args()
    if not (1 <= args.seeds <= 100 and 0.0 <= args.wind_sigma <= 30.0):
        ap.error('--seeds must be 1-100 and --wind-sigma 0-30 m/s')
    WIND_SIGMA[0] = args.wind_sigma
    changes = {k: _value(v) for k, v in (item.split('=', 1) for item in args.set)}
    compare = {k: _value(v) for k, v in (item.split('=', 1) for item in args.compare)}
    if args.wind_sigma > 0.0:
        changes.setdefault('wind_sigma', args.wind_sigma)
    TrackerSettings(**changes)  # validate before the long loop
    TrackerSettings(**{**changes, **compare})
    if args.modes and args.wind_sigma > 0.0:
        ap.error('--modes flies the true wind (no --wind-sigma)')
    cases = list(CASES) if args.all_cases else args.cases
    unknown = sorted(set(cases) - set(CASES))
    if unknown:
        ap.error(f'unknown case(s) {unknown}; the cases: {list(CASES)}')
    print(
        f'camera {RATE:g} Hz, noise {NOISE * 100:g} cm unless the case says, latency '
        f'{LATENCY * 1000:g} ms; '
        f'lead {args.lead:g} s; {args.flights} flights x {args.seeds} draws per case, seeds '
        f'{args.seed}..{args.seed + args.seeds - 1}; wind '
        + (f'unknown (prior sigma {args.wind_sigma:g} m/s)' if args.wind_sigma else 'known')
        + (f'; tracker settings changed: {changes}' if changes else '')
        + (f'; compared: {compare} on top' if compare else '')
    )
    for case in cases:
        ci, spec = list(CASES).index(case), CASES[case]
        if spec.gust:
            print(f'\ncase: {case}: no bound (the model flies a steady wind; with the gust '
                  'known the bound is the still-air one, with it unknown it is not defined)')
            continue
        t0 = time.perf_counter()
        t_lands, jacs, trk, fixes, maps, modes = [], [], [], [], [], []
        for draw in range(args.seed, args.seed + args.seeds):  # the benchmark's seeding
            releases = random_releases(np.random.default_rng(draw * 1000 + ci), args.flights,
                                       CASES[case])
            for k, release in enumerate(releases):
                seed = draw * 100000 + ci * 1000 + k
                t_land, xy_land, obs, model = flight_setup(
                    release, seed, args.lead, spec, args.wind_sigma
                )
                t_lands.append(t_land)
                fixes.append(len(obs))
                jacs.append(jacobians(release, model, xy_land))
                if args.tracker:
                    trk.append(tracker_errors(release, obs, xy_land, spec, changes,
                                              getattr(model, 'told', None), args.tracker_rows,
                                              compare))
                if args.modes:
                    modes.append(find_modes(release, obs, model, spec))
                if args.map:
                    maps.append(map_errors(release, obs, model, xy_land, spec))
        t_lands = np.array(t_lands)
        rate = f'{spec.rate:g} Hz' if spec.rate else '10-30 Hz'
        print(f'\ncase: {case} ({spec.ball}, {rate}, {spec.noise * 100:g} cm; '
              f'{time.perf_counter() - t0:.0f} s; fixes per flight {min(fixes)}-{max(fixes)})')
        masks = [('all', np.ones(t_lands.size, bool))] + [
            (name, (t_lands >= lo) & (t_lands < hi)) for name, lo, hi in CLASSES
        ]
        head = ''.join(f'{f"{name} (n={m.sum()})":>26}' for name, m in masks)
        print(f'{"landing error at the bound [cm]":>40}{head}')
        print(f'{"":>40}' + f'{"med(med)  pooled +/- sd":>26}' * len(masks))

        def row(label: str, sigmas: dict) -> np.ndarray:
            c = np.array([posterior(j, sigmas, spec.noise)[0] for j in jacs])
            meds = np.array([radial_median(x) for x in c])
            cells = bound_cells(masks, meds,
                                lambda m: pooled_medians(c[m], args.draws, seed=1))
            print(f'{label:>40}{cells}')
            return meds

        meds = {}
        for pname in PRIOR_NAMES:
            for kname, known in KNOWN.items():
                meds[(pname, kname)] = row(f'{pname} prior, {kname}',
                                           prior_sigmas(spec, pname, known))
        cells = []
        for kname, known in KNOWN.items():
            c = np.array([posterior(j, prior_sigmas(spec, 'benchmark', known), spec.noise)[0]
                          for j in jacs])
            cells.append(f'{kname} {np.mean(pooled_medians(c, args.draws, 1) <= 0.05):.3f}')
        print(f'{"P(median <= 5 cm) at the bound":>40}   benchmark prior: ' + ', '.join(cells))
        print('sensitivity (benchmark prior, neither known, but):')
        for scale in (0.2, 0.1, 0.05):
            row(f'scale sigma {scale:g}', prior_sigmas(spec, 'benchmark', kd=scale, kl=scale))
        for frac in (0.5, 0.25):
            row(f'spin sigma x {frac:g}',
                prior_sigmas(spec, 'benchmark', spin=frac * priors(spec)['benchmark'][1]))
        row('release point known (0, 0, 1.8)',
            prior_sigmas(spec, 'benchmark', ('x0', 'y0', 'z0')))
        row('axis offsets known', prior_sigmas(spec, 'benchmark', ('alpha0', 'beta0')))
        gmeds = None
        if args.modes:
            gmeds = global_rows(spec, jacs, modes, t_lands, masks, args.draws, trk)
        if args.map:
            print(f'{"batch MAP on the same fixes [cm]":>40}'
                  + f'{"median  (x bound)":>26}' * len(masks))
            for kname in KNOWN:
                err = np.array([mp[kname] for mp in maps])
                ratio = err / meds[('benchmark', kname)]
                cells = ''.join(
                    f'{np.median(err[m]) * 100:>16.2f}  (x {np.median(ratio[m]):.2f})'
                    if m.any() else f'{"-":>26}' for _, m in masks
                )
                print(f'{"MAP, " + kname:>40}{cells}')
        if not args.tracker:
            continue
        print(f'{"tracker replay [cm]":>40}' + f'{"median  (x bound)":>26}' * len(masks))
        for kname in trk[0]:
            err = np.array([t[kname][0] for t in trk])
            ratio = err / meds[('benchmark', BOUND_ROW.get(kname, kname))]  # 1 at the limit
            cells = ''
            for _, m in masks:
                if not m.any():
                    cells += f'{"-":>26}'
                    continue
                cells += f'{np.nanmedian(err[m]) * 100:>16.2f}  (x {np.nanmedian(ratio[m]):.2f})'
            print(f'{"tracker, " + kname:>40}{cells}')
            nees = np.array([t[kname][3] for t in trk])
            if BOUND_ROW.get(kname, kname) == 'neither known' and gmeds is not None:
                print(f'{"x global bound":>40}' + ''.join(
                    f'{f"x {np.nanmedian(err[m] / gmeds[m]):.2f}":>26}' if m.any()
                    else f'{"-":>26}' for _, m in masks))
            print(f'{"NEES mean, in 95 % ellipse":>40}' + ''.join(
                f'{f"{np.nanmean(nees[m]):.2f}  {np.mean(nees[m] <= CHI2_2_95):.2f}":>26}'
                if m.any() else f'{"-":>26}' for _, m in masks))
        if 'neither known' not in trk[0]:
            continue
        # The spin: the tracker's |spin| error against the bound's (median of |N(0, var)|).
        spin_err = np.array([t['neither known'][1] for t in trk])
        spin_bound = []
        for j in jacs:
            _, cov, names = posterior(j, prior_sigmas(spec, 'benchmark'), spec.noise)
            spin_bound.append(QUARTILE * math.sqrt(cov[names.index('spin'), names.index('spin')]))
        spin_bound = np.array(spin_bound) / RPM
        hand = np.array([t['neither known'][2] for t in trk])
        cells = ''.join(
            f'{np.nanmedian(spin_err[m]):>16.0f}  (x {np.nanmedian(spin_bound[m]):.0f})'
            if m.any() else f'{"-":>26}' for _, m in masks
        )
        print(f'{"|spin| error [rpm] (bound median)":>40}{cells}')
        print(f'{"hand right (tracker, neither known)":>40}'
              + ''.join(f'{f"{hand[m].sum()}/{m.sum()}":>26}' for _, m in masks))


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    # Its own section for the wind unknown, another lead time and the tracker's batch fit.
    pre = argparse.ArgumentParser(add_help=False)
    pre.add_argument('--wind-sigma', type=float, default=0.0)
    pre.add_argument('--lead', type=float, default=1.0)
    pre.add_argument('--set', nargs='*', default=[])
    pre.add_argument('--cases', nargs='*', default=[])
    flags, _ = pre.parse_known_args()
    field_only = bool(flags.cases) and all(c in _benchmark.FIELD_CASES for c in flags.cases)
    fitted = any(item.startswith('refine_iterations=') and item.split('=', 1)[1].strip('0')
                 for item in flags.set)
    section = ('prediction bound' + (', field cases' if field_only else '')
               + (', wind unknown' if flags.wind_sigma > 0.0 else '')
               + (f', lead {flags.lead:g} s' if flags.lead != 1.0 else '')
               + (', tracker with the batch fit' if fitted else ''))
    raise SystemExit(results.recorded(section, main))
