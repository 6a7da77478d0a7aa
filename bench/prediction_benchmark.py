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
Landing prediction benchmark (headless, seeded): the tracker against two common baselines.

Many full-model flights (both hands, a spread of speeds, elevations, spins and release angles)
are seen by the simulated camera (60 Hz, 2 cm noise, 20 ms latency). At lead times 1.5, 1.0
and 0.5 s before the true landing, with the fixes delivered by then, each method predicts the
landing point and time:
- tracker: football_ros.estimation.FlightTracker (UKF on the full model, its predictions from
  the batch fit of every fix once the hand is known);
- filter: the same tracker without the batch fit (refine_iterations 0), fed the same fixes;
- parabola: least-squares quadratic in t per axis, landing where z(t) = 0;
- drag: point mass with quadratic drag a = -c |v| v - g, fitted (r0, v0, c) by nonlinear least
  squares to the same fixes;
- oracle: the tracker told the true |spin| and the true coefficients (an information limit:
  what the tracker could do if the throw's unknowns were known; only the hand is left).
Cases (:data:`CASES`): the defaults; true drag and lift 30 % off both ways; an unknown 5 m/s
crosswind; rugby screw kicks at 60-600 rpm (gyroscopically unstable below about 230 rpm); long
bombs carrying 50-60 m; the camera at 30 and 120 Hz; 5 mm and 5 cm noise; and the field's
(:data:`FIELD_CASES`: a 10-30 Hz camera, stamp jitter 1-10 ms, a mono camera's depth noise 5-20x
the lateral told per fix, rugby kicks at 0-120 rpm, end over end at 20-120 rpm, a crosswind gust
of 2-8 m/s over 0.5-2 s; no oracle). ``--clutter`` adds false detections, ``--wind-sigma`` lets
the tracker estimate the wind from the start (``--gust-rate``: its gusty twins' rate, 0 = still
air only; by default the tracker's), ``--draws`` repeats a case over independent seeds (the
summary gives the median of the per-draw medians and their range).
NEES: mean over the flights of e' C^-1 e (e the landing point error, C the published 2x2
covariance): 2 for an honest covariance (above: overconfident), and the fraction inside the
95 % ellipse. Also prints the tracker's time per fix (update, and update + landing
prediction) against the 16.7 ms frame, wall and CPU.

Information limit of the same flights and fixes: bench/prediction_bound.py. The figures of both
are in bench/RESULTS.md.

    .venv/bin/python bench/prediction_benchmark.py [--flights 60] [--draws 5] [--cases ...]
        [--unstable-fits] [--every 2]  # the node's cadence: a prediction after every 2nd fix
    .venv/bin/python bench/prediction_benchmark.py --cameras [--rigs mono ...]  # config/rig_*
"""

from __future__ import annotations

import argparse
import collections
from dataclasses import dataclass, field, replace
import importlib
import itertools
import math
import time

from football_ros.estimation import (
    Camera,
    CameraSettings,
    FlightTracker,
    Observation,
    TrackerSettings,
)
from football_ros.estimation.bound import radial_median
from football_ros.estimation.multi import MultiTracker
from football_ros.physics import Flight, Release
from football_ros.physics.aero import AeroModel
from numba import njit
import numpy as np
from scipy.optimize import least_squares

LEADS = (1.5, 1.0, 0.5)
RATE, NOISE, LATENCY = 60.0, 0.02, 0.02
CHI2_2_95 = 5.991  # chi-square 2 dof, 95 %: an honest covariance has NEES mean 2, 95 % inside
G = 9.81
DEFAULT = AeroModel()


@dataclass(frozen=True)
class Case:
    """
    One benchmark case: the true air and throws, and the camera.

    ``aero``: the flights' true coefficients and wind (the tracker assumes the defaults);
    ``spin`` |rpm|, ``speed`` [m/s] and ``elevation`` [deg] ranges drawn uniformly; ``carry``
    [m]: keep only throws whose full-model carry lies in it; camera ``rate`` [Hz] and ``noise``
    [m] (the tracker is told the noise and the ball). The field's cases: ``jitter`` (lo, hi)
    [s] 1-sigma jitter of the stamps drawn per flight (the tracker not told); ``depth`` (lo,
    hi) the noise along y (a mono camera on the sideline looking along y) as a multiple of
    ``noise`` drawn per flight, each fix's covariance told; ``gust`` ((lo, hi) [m/s], (lo, hi)
    [s]): a crosswind (along +/- y) ramping from 0 to a size over a duration, starting at a
    time drawn in the first half of the flight; ``tumble`` (lo, hi) [rev/min]: end over end, a
    pitch rate about a transverse axis at the release (beside ``spin`` about the long axis).
    """

    aero: dict = field(default_factory=dict)
    ball: str = 'american'
    spin: tuple = (400.0, 800.0)
    speed: tuple = (16.0, 29.0)
    elevation: tuple = (18.0, 45.0)
    carry: tuple | None = None
    rate: float = RATE
    noise: float = NOISE
    jitter: tuple | None = None
    depth: tuple | None = None
    gust: tuple | None = None
    tumble: tuple | None = None


CASES = {
    'defaults': Case(),
    'crosswind 5 m/s': Case(aero={'wind': (0.0, 5.0, 0.0)}),
    'drag +30%, lift -30%': Case(
        aero={
            'c_d0': DEFAULT.c_d0 * 1.3,
            'c_d2': DEFAULT.c_d2 * 1.3,
            'c_l_alpha': DEFAULT.c_l_alpha * 0.7,
        }
    ),
    'drag -30%, lift +30%': Case(
        aero={
            'c_d0': DEFAULT.c_d0 * 0.7,
            'c_d2': DEFAULT.c_d2 * 0.7,
            'c_l_alpha': DEFAULT.c_l_alpha * 1.3,
        }
    ),
    'rugby 60-600 rpm': Case(ball='rugby', spin=(60.0, 600.0)),
    'long bombs 50-60 m': Case(speed=(20.0, 27.0), elevation=(30.0, 45.0), carry=(50.0, 60.0)),
    '30 Hz': Case(rate=30.0),
    '120 Hz': Case(rate=120.0),
    '5 mm noise': Case(noise=0.005),
    '5 cm noise': Case(noise=0.05),
}
FIELD_CASES = {
    'camera 10-30 Hz': Case(rate=None),
    'stamp jitter 1-10 ms': Case(jitter=(0.001, 0.01)),
    'mono depth 5-20x': Case(noise=0.01, depth=(5.0, 20.0)),
    'rugby 0-120 rpm': Case(ball='rugby', spin=(0.0, 120.0)),
    'end over end 20-120 rpm': Case(ball='rugby', spin=(0.0, 30.0), tumble=(20.0, 120.0)),
    'gust 2-8 m/s over 0.5-2 s': Case(gust=((2.0, 8.0), (0.5, 2.0))),
}
"""Issue 32's cases (the field): drawn per flight where a range is given (the rate too)."""
CASES.update(FIELD_CASES)


def random_releases(rng: np.random.Generator, n: int, case: Case) -> list[Release]:
    """Return ``n`` full-model releases of ``case`` (both hands), drawn from ``rng``."""
    out = []
    while len(out) < n:
        hand = 1.0 if rng.random() < 0.5 else -1.0
        tumble = (
            {'alpha_rate_deg_s': 6.0 * float(rng.uniform(*case.tumble))} if case.tumble else {}
        )
        release = Release(
            ball=case.ball,
            speed=float(rng.uniform(*case.speed)),
            elevation_deg=float(rng.uniform(*case.elevation)),
            azimuth_deg=float(rng.uniform(-20.0, 20.0)),
            spin_rpm=hand * float(rng.uniform(*case.spin)),
            alpha0_deg=float(rng.normal(0.0, 1.5)),
            beta0_deg=float(rng.normal(0.0, 1.5)),
            position=(0.0, 0.0, 1.8),
            model='full',
            aero=case.aero,
            **tumble,
        )
        if case.carry is not None:
            end = Flight.from_release(release).simulate(rate=100.0, duration=20.0).positions[-1]
            if not case.carry[0] <= math.hypot(end[0], end[1]) <= case.carry[1]:
                continue
        out.append(release)
    return out


TOLD: dict = {}
"""The tracker's settings of this run beyond the case's (``--gust-rate``, ``--gust-prior``,
``--unstable-fits``; absent: the tracker's defaults)."""


def tracker_settings(case: Case, wind_sigma: float = 0.0) -> TrackerSettings:
    """Return what the tracker is told in ``case``: the ball, the camera's noise, the wind's."""
    return TrackerSettings(noise=case.noise, ball=case.ball, wind_sigma=wind_sigma, **TOLD)


# --- baselines ----------------------------------------------------------------------------------
def parabola_landing(t: np.ndarray, z: np.ndarray):
    """Quadratic fit per axis; the landing is the later root of z(t) = 0."""
    t0 = t[-1]
    tau = t - t0
    A = np.column_stack([np.ones_like(tau), tau, tau**2])
    coef, *_ = np.linalg.lstsq(A, z, rcond=None)
    c, b, a = coef[0, 2], coef[1, 2], coef[2, 2]
    if a >= 0:
        return None
    disc = b * b - 4 * a * c
    if disc < 0:
        return None
    root = (-b - math.sqrt(disc)) / (2 * a)
    xy = coef[0, :2] + coef[1, :2] * root + coef[2, :2] * root**2
    return t0 + root, xy


@njit(cache=True)
def _drag_track(p, times, out):
    """Point mass with a = -c|v|v - g z from p = (r0, v0, c) at times[0]; positions at times."""
    y = p[:6].copy()
    c = p[6]
    out[0] = y[:3]
    t = times[0]
    k = np.empty(6)
    for i in range(1, times.size):
        dt_total = times[i] - t
        n = max(1, int(math.ceil(dt_total / 0.01)))
        h = dt_total / n
        for _ in range(n):
            y0 = y.copy()
            acc = np.zeros((4, 6))
            for stage in range(4):
                if stage == 0:
                    yy = y0
                elif stage < 3:
                    yy = y0 + 0.5 * h * acc[stage - 1]
                else:
                    yy = y0 + h * acc[2]
                sp = math.sqrt(yy[3] ** 2 + yy[4] ** 2 + yy[5] ** 2)
                k[0], k[1], k[2] = yy[3], yy[4], yy[5]
                k[3], k[4], k[5] = -c * sp * yy[3], -c * sp * yy[4], -c * sp * yy[5] - 9.81
                acc[stage] = k
            y = y0 + h / 6.0 * (acc[0] + 2 * acc[1] + 2 * acc[2] + acc[3])
        t = times[i]
        out[i] = y[:3]
    return y


def drag_landing(t: np.ndarray, z: np.ndarray, guess_v: np.ndarray):
    """Fit (r0, v0, c) to the fixes; integrate to z = 0 from the last fix time."""
    out = np.empty((t.size, 3))

    def residual(p):
        _drag_track(p, t, out)
        return (out - z).ravel()

    p0 = np.concatenate([z[0], guess_v, [0.005]])
    fit = least_squares(residual, p0, method='lm', x_scale='jac')
    p = fit.x
    times = np.array([t[0], t[-1]])
    tmp = np.empty((2, 3))
    y = _drag_track(p, times, tmp)
    # March on in 5 ms steps to the ground.
    state = np.concatenate([y, [p[6]]])
    tt = t[-1]
    for _ in range(4000):
        nxt = np.empty((2, 3))
        y2 = _drag_track(state, np.array([0.0, 0.005]), nxt)
        if y2[2] <= 0.0:
            frac = state[2] / (state[2] - y2[2])
            return tt + 0.005 * frac, state[:2] + frac * (y2[:2] - state[:2])
        state = np.concatenate([y2, [p[6]]])
        tt += 0.005
    return None


# --- one flight ---------------------------------------------------------------------------------
def camera_fixes(release: Release, seed: int, t_land: float, case: Case = CASES['defaults']):
    """
    Return the seeded camera's observations of a flight captured before its landing [s].

    The camera (``case``'s rate and noise) runs to the landing + 1 s (:meth:`Camera.record`:
    nothing dropped).
    """
    flight = Flight.from_release(release)
    rng = np.random.default_rng(seed)
    cam = Camera(CameraSettings(rate=case.rate, noise=case.noise, latency=LATENCY, seed=seed))
    cam.restart(float(rng.uniform(0.0, 1.0 / case.rate)))
    obs = cam.record(t_land + 1.0, lambda t: flight.state_at(t)[:3])
    return [o for o in obs if o.stamp < t_land]


def gust_flight(release: Release, size: float, start: float, duration: float):
    """
    Fly ``release`` through a crosswind gust: the wind's y goes 0 -> ``size`` [m/s] linearly.

    From ``start`` [s] over ``duration`` [s] after the release, then stays (the full model's
    own step and parameters, the wind set at each 1 ms step). Returns times (n,) [s] and
    positions (n, 3) [m] to the landing (the last row on the ground).
    """
    from football_ros.physics import dynamics as dyn

    flight = Flight.from_release(release)
    y, params = flight.y0.copy(), flight.params.copy()
    nxt, work = np.empty_like(y), np.empty((5, y.size))
    h, t = 0.001, 0.0
    times, pos = [0.0], [y[:3].copy()]
    while t < 30.0:
        params[dyn.P_WIND + 1] = size * min(max((t + 0.5 * h - start) / duration, 0.0), 1.0)
        dyn.rk4_step_with(y, h, params, nxt, work)
        if dyn.crossed_ground(y, nxt, 0.0):
            tau = dyn.landing_time_in_step(y, h, params, 0.0)
            dyn.rk4_step_with(y, tau, params, nxt, work)
            times.append(t + tau)
            pos.append(nxt[:3].copy())
            break
        y[:] = nxt
        t += h
        times.append(t)
        pos.append(y[:3].copy())
    return np.array(times), np.array(pos)


def field_fixes(release: Release, seed: int, case: Case):
    """
    Return a field case's fixes before the landing, the landing time [s] and x y [m].

    Fixes: (Observation, covariance (3, 3) told to the tracker or None); the capture time is
    the delivery - LATENCY. The rate (drawn in 10-30 Hz where ``case.rate`` is None), stamp
    jitter, a mono camera's depth noise and a gust are drawn per flight (:class:`Case`; the
    draws in a 4th item {'rate', 'jitter', 'depth'}); no dropouts or outliers.
    """
    rng = np.random.default_rng(seed + 7)
    rate = case.rate or float(rng.uniform(10.0, 30.0))
    jitter = float(rng.uniform(*case.jitter)) if case.jitter else 0.0
    depth = float(rng.uniform(*case.depth)) if case.depth else 1.0
    if case.gust:
        size = float(rng.uniform(*case.gust[0])) * (1.0 if rng.random() < 0.5 else -1.0)
        duration = float(rng.uniform(*case.gust[1]))
        probe = Flight.from_release(release).simulate(rate=100.0, duration=20.0)
        start = float(rng.uniform(0.0, 0.5 * probe.times[-1]))
        times, pos = gust_flight(release, size, start, duration)
    else:
        truth = Flight.from_release(release).simulate(rate=1000.0, duration=20.0)
        times, pos = truth.times, truth.positions
    t_land = float(times[-1])
    sig = case.noise * np.array([1.0, depth, 1.0])
    cov = np.diag(sig**2) if case.depth else None
    out = []
    for t in np.arange(float(rng.uniform(0.0, 1.0 / rate)), t_land, 1.0 / rate):
        z = np.array([np.interp(t, times, pos[:, i]) for i in range(3)]) + rng.normal(0.0, sig)
        stamp = t + float(rng.normal(0.0, jitter)) if jitter else t
        out.append((Observation(float(stamp), z, t + LATENCY), cov))
    return out, t_land, pos[-1, :2], {'rate': rate, 'jitter': jitter, 'depth': depth}


def with_clutter(obs: list, rate: float, seed: int) -> list:
    """
    Return ``obs`` with false detections added at ``rate`` [Hz], in delivery order.

    Uniform anywhere over the field (a 55 x 40 x 12 m box), delivered with the camera's latency.
    """
    if rate <= 0.0 or not obs:
        return obs
    rng = np.random.default_rng(seed + 7919)
    t0, t1 = obs[0].stamp, obs[-1].stamp
    stamps = np.arange(t0, t1, 1.0 / rate) + 0.5 / rate
    fake = [
        Observation(float(t), rng.uniform((-5.0, -20.0, 0.0), (50.0, 20.0, 12.0)), t + LATENCY)
        for t in stamps
    ]
    return sorted(obs + fake, key=lambda o: o.delivery)


SECOND_BALL = Release(
    model='full', speed=20.0, elevation_deg=40.0, spin_rpm=-500.0, azimuth_deg=30.0,
    position=(10.0, 5.0, 1.5),
)
"""The other ball of ``--two-balls``: released 0.3 s after each benchmark throw, seen too."""


def flight_fixes(release: Release, seed: int, case: Case) -> tuple[list, float, np.ndarray]:
    """
    Return a flight's fixes [(Observation, told covariance or None)], landing time [s], point.

    A field case's own fixes (:func:`field_fixes`), else the camera's of the case
    (:func:`camera_fixes`) on the flown truth; the landing point [m] in ``field`` x, y.
    """
    if any(case is c for c in FIELD_CASES.values()):
        fixes, t_land, xy_land, _ = field_fixes(release, seed, case)
        return fixes, t_land, xy_land
    truth = Flight.from_release(release).simulate(rate=100.0, duration=20.0)
    t_land = float(truth.times[-1])
    return ([(o, None) for o in camera_fixes(release, seed, t_land, case)], t_land,
            truth.positions[-1, :2])


def run_flight(
    release: Release,
    seed: int,
    case: Case = CASES['defaults'],
    wind_sigma: float = 0.0,
    oracle: bool = True,
    clutter: float = 0.0,
    two_balls: bool = False,
    every: int = 0,
):
    """
    Replay one flight's fixes into the tracker (and the oracle) and the baselines.

    ``every`` > 0: the tracker also predicts after every ``every``-th observation delivered, as
    the node does (its fits then followed from prediction to prediction); 0: only at the leads.
    ``two_balls``: the camera also sees :data:`SECOND_BALL` (released 0.3 s later, its own
    noise) and the tracker is a :class:`MultiTracker`, judged on the track that took most of
    this ball's fixes (the baselines are handed this ball's fixes alone; no oracle).
    Returns {lead: {method: (error [m], time error [s], NEES) or None}} and the flight time [s].
    """
    fixes, t_land, xy_land = flight_fixes(release, seed, case)
    told = {id(o): c for o, c in fixes if c is not None}  # where the tracker is told one
    obs = [(o, True) for o, _ in fixes]
    if any(case is c for c in FIELD_CASES.values()):
        oracle = False
    if two_balls:
        t2 = float(Flight.from_release(SECOND_BALL).simulate(rate=100.0).times[-1])
        other = camera_fixes(SECOND_BALL, seed + 50021, t2, case)
        obs += [(Observation(o.stamp + 0.3, o.position, o.delivery + 0.3), False) for o in other]
        oracle = False
    flat = with_clutter([o for o, _ in obs], clutter, seed)
    mine = {id(o) for o, own in obs if own}
    obs = sorted(flat, key=lambda o: o.delivery)
    settings = tracker_settings(case, wind_sigma)
    tracker = MultiTracker(settings) if two_balls else FlightTracker(settings)
    alone = None if two_balls else FlightTracker(replace(settings, refine_iterations=0))
    routed = collections.Counter()  # track id -> this ball's fixes it took
    known = FlightTracker(
        TrackerSettings(
            noise=case.noise,
            ball=case.ball,
            spin_rpm=abs(release.spin_rpm),
            spin_sigma=0.01,
            scale_sigma=0.01,
            aero=release.aero_model(),
        )
    ) if oracle else None
    results = {}
    delivered_t, delivered_z = [], []
    i = 0
    for lead in sorted(LEADS, reverse=True):
        t_eval = t_land - lead
        while i < len(obs) and obs[i].delivery <= t_eval:
            o = obs[i]
            i += 1
            cov = told.get(id(o))
            got = tracker.update(o.stamp, o.position, covariance=cov)
            if every and i % every == 0:
                tracker.predict_landing()
            if alone is not None:
                alone.update(o.stamp, o.position, covariance=cov)
            if id(o) not in mine:
                continue
            if two_balls and got[0] is not None:
                routed[got[0]] += 1
            if oracle:
                known.update(o.stamp, o.position)
            delivered_t.append(o.stamp)
            delivered_z.append(o.position)
        row = {}
        if two_balls:
            best = routed.most_common(1)[0][0] if routed else None
            track = tracker.tracks.get(best)
            pred = track.predict_landing() if track is not None else None
        else:
            pred = tracker.predict_landing()
        row['tracker'] = None if pred is None else (pred.time, pred.position[:2], pred.covariance)
        pred = alone.predict_landing() if alone is not None else None
        row['filter'] = None if pred is None else (pred.time, pred.position[:2], pred.covariance)
        pred = known.predict_landing() if oracle else None
        row['oracle'] = None if pred is None else (pred.time, pred.position[:2], pred.covariance)
        t_arr, z_arr = np.array(delivered_t), np.array(delivered_z)
        if len(t_arr) >= 6:
            par = parabola_landing(t_arr, z_arr)
            row['parabola'] = par
            guess = (z_arr[5] - z_arr[0]) / (t_arr[5] - t_arr[0])
            row['drag'] = drag_landing(t_arr, z_arr, guess)
        else:
            row['parabola'] = row['drag'] = None
        results[lead] = {
            k: (None if v is None else _errors(v, xy_land, t_land)) for k, v in row.items()
        }
    return results, t_land


CAMERA_RIGS = {  # the ``cameras`` case set: rig name -> rig file (config/)
    'two 60 Hz sideline cameras': 'rig_sideline.yaml',
    '1 m stereo pair, 120 Hz': 'rig_stereo.yaml',
    'one 120 Hz camera': 'rig_mono.yaml',
}
CAMERA_BASELINE = '1 m stereo pair, 120 Hz'
"""The rig whose synchronised pairs the baseline triangulates."""


def rig_key(file: str) -> str:
    """Return a rig file's short name for ``--rigs``: rig_mono.yaml -> 'mono'."""
    return file.removeprefix('rig_').removesuffix('.yaml')


def triangulate(cam_a, uv_a, cam_b, uv_b) -> np.ndarray:
    """Midpoint of the closest points of two pixels' rays [m] in ``field``."""
    rays = []
    for cam, uv in ((cam_a, uv_a), (cam_b, uv_b)):
        d = cam.rotation @ cam.unproject(np.asarray(uv, dtype=float))
        rays.append((cam.position, d / np.linalg.norm(d)))
    (p, d), (q, e) = rays
    w = p - q
    b, dd, ee = d @ e, d @ w, e @ w
    den = 1.0 - b * b
    s_, t_ = (b * ee - dd) / den, (ee - b * dd) / den
    return 0.5 * (p + s_ * d + q + t_ * e)


def run_camera_flight(release: Release, seed: int, rig) -> tuple[dict, dict, float]:
    """
    Replay one flight's rig detections into the pixel tracker; compute the bound at each lead.

    For a synchronised pair also the triangulating baseline; the bound in pixel space.

    Returns ({lead: {method: (error [m], time error [s], NEES) or None}}, {lead: bound
    median [m]}, flight time [s]).
    """
    import dataclasses

    from football_ros.estimation.camera_fusion import CameraFusion
    from football_ros.estimation.detections import sampled_flight, simulate
    from football_ros.physics import get_preset
    bound = importlib.import_module('prediction_bound')

    ball = get_preset(release.ball)
    truth = Flight.from_release(release).simulate(rate=1000.0, duration=20.0)
    t_land = float(truth.times[-1])
    xy_land = truth.positions[-1, :2]
    rng = np.random.default_rng(seed)
    rig = tuple(dataclasses.replace(c, seed=seed * 31 + k) for k, c in enumerate(rig))
    shift = float(rng.uniform(0.0, 1.0 / max(c.rate for c in rig)))  # release vs the frames
    rig = tuple(dataclasses.replace(c, phase=c.phase + shift) for c in rig)
    balls_at = sampled_flight(truth.times, truth.positions, truth.velocities, truth.axes)
    frames = [f for f in simulate(rig, balls_at, 0.0, t_land, ball.length, ball.diameter)
              if f.stamp < t_land]
    cams = {c.name: c for c in rig}
    fusion = CameraFusion(FlightTracker(TrackerSettings(ball=release.ball)),
                          rig[0].pixel_noise, ball.diameter)
    pairs = {}  # exposure -> {camera: detection} for the baseline
    baseline_fixes = []
    for f in frames:
        if len(f.detections) == 1:
            pairs.setdefault(round(f.exposure, 9), {})[f.camera] = (f, f.detections[0])
    if len(rig) == 2:
        for exposure, both in sorted(pairs.items()):
            if len(both) == 2:
                (fa, da), (fb, db) = both[rig[0].name], both[rig[1].name]
                p = triangulate(cams[fa.camera].camera, da.center, cams[fb.camera].camera,
                                db.center)
                baseline_fixes.append((max(fa.delivery, fb.delivery), fa.stamp, p, exposure))
    if baseline_fixes:  # the isotropic noise a user would measure: RMS per axis of the fixes
        err = np.array([p - balls_at(e)[0][0] for _d, _s, p, e in baseline_fixes
                        if balls_at(e)[0].size])
        inliers = np.linalg.norm(err, axis=1) < np.percentile(np.linalg.norm(err, axis=1), 99)
        noise = float(np.sqrt(np.mean(err[inliers] ** 2)))
        noise = min(max(noise, 1e-3), 10.0)
        baseline = FlightTracker(TrackerSettings(ball=release.ball, noise=noise))
    else:
        baseline = None
    results, bounds = {}, {}
    i = j = 0
    for lead in sorted(LEADS, reverse=True):
        t_eval = t_land - lead
        while i < len(frames) and frames[i].delivery <= t_eval:
            f = frames[i]
            i += 1
            for d in f.detections:
                fusion.observe(f.stamp, cams[f.camera].camera, d.center, d.width)
        while baseline is not None and j < len(baseline_fixes) and baseline_fixes[j][0] <= t_eval:
            baseline.update(baseline_fixes[j][1], baseline_fixes[j][2])
            j += 1
        row = {}
        for name, tracker in (('pixels', fusion.tracker), ('triangulated', baseline)):
            pred = tracker.predict_landing() if tracker is not None else None
            row[name] = None if pred is None else _errors(
                (pred.time, pred.position[:2], pred.covariance), xy_land, t_land)
        results[lead] = row
        seen = [(f.exposure, cams[f.camera].camera, d.width, cams[f.camera].pixel_noise)
                for f in frames[:i] for d in f.detections if not d.outlier]
        try:  # no detection yet: no bound (NaN)
            bounds[lead] = (radial_median(bound.camera_bound(release, seen, CASES['defaults']))
                            if seen else math.nan)
        except (np.linalg.LinAlgError, ValueError):
            bounds[lead] = math.nan
    return results, bounds, t_land


def camera_main(args) -> None:
    """Run the ``cameras`` case set: the pixel tracker, the bound, the triangulating baseline."""
    from pathlib import Path

    from football_ros.estimation.rig import load_rig

    config = Path(__file__).resolve().parents[1] / 'config'
    print(
        f'cameras: config/rig_*.yaml (1080p, 60 deg, 1 px noise, 2 % dropouts, 1 % outliers, '
        f'0.1 ms stamp jitter, 30 ms latency); the release at a random phase of the frames; '
        f'{args.flights} flights x {args.draws} draws (defaults case), seeds {args.seed}..'
        f'{args.seed + args.draws - 1}. pixels: the tracker fed the detections as pixels '
        '(camera_fusion); triangulated: synchronised pairs triangulated, fed as isotropic '
        'fixes (noise = their RMS error per axis); bound: pixel-space Cramer-Rao bound '
        '(benchmark prior), its per-flight median |e|; ratio: median over flights of error / '
        'bound. NEES 2 and 0.95 inside the 95 % ellipse when honest.'
    )
    print(f'{"rig":>28} {"lead":>5} {"method":>13} {"n":>4} {"median":>7} {"rms":>7} '
          f'{"bound":>7} {"ratio":>6} {"NEES":>6} {"in 95%":>7}')
    for ri, (rig_name, file) in enumerate(CAMERA_RIGS.items()):
        if args.rigs and rig_key(file) not in args.rigs:
            continue  # the others' seeds stay as in the whole set (ri is the rig's place)
        rig = load_rig(config / file)
        per, bnd = [], []
        for seed in range(args.seed, args.seed + args.draws):
            rng = np.random.default_rng(seed * 1000 + 77)
            for k, r in enumerate(random_releases(rng, args.flights, CASES['defaults'])):
                res, bounds, _ = run_camera_flight(r, seed * 100000 + ri * 1000 + k, rig)
                per.append(res)
                bnd.append(bounds)
        for lead in (1.0, 0.5):
            for m in ('pixels', 'triangulated'):
                got = [(p[lead][m], b[lead]) for p, b in zip(per, bnd) if p[lead][m] is not None]
                if not got:
                    continue
                err = np.array([g[0][0] for g in got])
                nees = np.array([g[0][2] for g in got])
                b = np.array([g[1] for g in got])
                print(f'{rig_name:>28} {lead:>5.1f} {m:>13} {len(got):>4} {np.median(err):>7.3f} '
                      f'{np.sqrt(np.mean(err**2)):>7.3f} {np.nanmedian(b):>7.3f} '
                      f'{np.nanmedian(err / b):>6.2f} {np.mean(nees):>6.2f} '
                      f'{np.mean(nees <= CHI2_2_95):>7.2f}')


def _errors(pred, xy_land, t_land) -> tuple[float, float, float]:
    """
    Return the landing point error [m], the landing time error [s] and the NEES.

    NEES of the landing point: e' C^-1 e with the published covariance C, NaN for the baselines
    that give none.
    """
    err = np.asarray(pred[1]) - xy_land
    nees = float(err @ np.linalg.solve(pred[2], err)) if len(pred) > 2 else math.nan
    return float(np.linalg.norm(err)), float(pred[0] - t_land), nees


def time_tracker(releases: list[Release], seed: int) -> dict[str, np.ndarray]:
    """
    Time per fix [ms] of update() and of update() + predict_landing(), wall and CPU.

    CPU time of this thread; replaying the camera fixes of ``releases`` (nothing else running).
    """
    out = {
        'update wall': [],
        'update cpu': [],
        'update+landing wall': [],
        'update+landing cpu': [],
    }
    for k, release in enumerate(releases):
        t_land = float(Flight.from_release(release).simulate(rate=100.0, duration=20.0).times[-1])
        obs = camera_fixes(release, seed + k, t_land)
        for with_landing in (False, True):
            tracker = FlightTracker()
            key = 'update+landing' if with_landing else 'update'
            for o in obs:
                w0, c0 = time.perf_counter(), time.thread_time()
                tracker.update(o.stamp, o.position)
                if with_landing:
                    tracker.predict_landing()
                out[key + ' wall'].append(time.perf_counter() - w0)
                out[key + ' cpu'].append(time.thread_time() - c0)
    return {k: np.array(v) * 1e3 for k, v in out.items()}


def _summary_rows(name: str, per: list, t_flights: np.ndarray, draws: np.ndarray) -> list[str]:
    """
    Return the rows of one case at 1.0 and 0.5 s lead, and its flights > 2.8 s at 1.0 s.

    The tracker's, and the filter alone's (without the batch fit) after each.
    """
    rows = []
    for label, keep in ((name, np.ones(len(per), bool)), (name + ', > 2.8 s', t_flights > 2.8)):
        for lead, method in itertools.product((1.0, 0.5), ('tracker', 'filter')):
            got = [
                (per[i][lead][method], draws[i])
                for i in np.flatnonzero(keep)
                if per[i][lead][method] is not None
            ]
            if not got or (label != name and lead != 1.0):
                continue
            shown = label + (', filter alone' if method == 'filter' else '')
            err = np.array([g[0][0] for g in got])
            nees = np.array([g[0][2] for g in got])
            d = np.array([g[1] for g in got])
            medians = [np.median(err[d == k]) for k in np.unique(d)]
            rows.append(
                f'{shown:>42} {lead:>5.1f} {len(got):>4} {np.median(medians):>7.3f} '
                f'{min(medians):>7.3f}-{max(medians):<7.3f} {np.mean(nees):>6.2f} '
                f'{np.mean(nees <= CHI2_2_95):>7.2f}'
            )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument('--flights', type=int, default=60, help='flights per case')
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--cases', nargs='*', default=list(CASES))
    ap.add_argument(
        '--wind-sigma',
        type=float,
        default=0.0,
        help='the tracker estimates the horizontal wind with this prior sigma [m/s] (0 = not)',
    )
    ap.add_argument('--gust-rate', type=float, default=None,
                    help="the tracker's gust_rate [m/s/sqrt(s)] (default: the tracker's, "
                         f'{TrackerSettings.gust_rate:g}; 0 = still air only)')
    ap.add_argument('--gust-prior', type=float, default=None,
                    help="the tracker's gust_prior, the odds of gusty air (default: the "
                         f"tracker's, {TrackerSettings.gust_prior:g}; docs/tracker.md's gusty "
                         'day: 0.5)')
    ap.add_argument('--draws', type=int, default=1, help='independent draws (seeds seed..)')
    ap.add_argument(
        '--clutter', type=float, default=0.0, help='false detections per second [Hz] added'
    )
    ap.add_argument(
        '--two-balls', action='store_true', help='a second ball in the air (SECOND_BALL)'
    )
    ap.add_argument('--cameras', action='store_true',
                    help='the cameras case set (config/rig_*.yaml) instead of the cases')
    ap.add_argument('--rigs', nargs='*', default=[],
                    choices=[rig_key(f) for f in CAMERA_RIGS.values()],
                    help='with --cameras: only these rigs (each on the seeds it has in the '
                         'whole set)')
    ap.add_argument('--unstable-fits', action='store_true',
                    help="the tracker's unstable_fits on (the multi-start fits of unstable kicks)")
    ap.add_argument('--every', type=int, default=0,
                    help='the tracker also predicts after every n-th fix, as the node does '
                         '(2: 30 a second at 60 Hz; 0: only at the leads)')
    args = ap.parse_args()
    if not 0 <= args.every <= 1000:
        ap.error(f'--every {args.every}: 0 (only at the leads) to 1000')
    TOLD.update({name: value for name, value in (('gust_rate', args.gust_rate),
                                                 ('gust_prior', args.gust_prior),
                                                 ('unstable_fits', args.unstable_fits or None))
                 if value is not None})
    if args.cameras:
        camera_main(args)
        return
    unknown = sorted(set(args.cases) - set(CASES))
    if unknown:
        ap.error(f'unknown case(s) {unknown}; the cases: {list(CASES)}')
    # Warm the compiled kernels so that the timings are of the steady state.
    run_flight(Release(model='full'), 0)
    methods = ('tracker', 'filter', 'oracle', 'drag', 'parabola')
    print(
        f'camera {RATE:g} Hz, noise {NOISE * 100:g} cm, latency {LATENCY * 1000:g} ms unless the '
        f'case says; {args.flights} flights per case x {args.draws} draws, seeds {args.seed}..'
        f'{args.seed + args.draws - 1}, tracker wind_sigma {args.wind_sigma:g} m/s, '
        f'gust_rate {tracker_settings(CASES["defaults"]).gust_rate:g} m/s/sqrt(s), '
        f'gust_prior {tracker_settings(CASES["defaults"]).gust_prior:g}, '
        f'clutter {args.clutter:g} Hz' + (', a second ball' if args.two_balls else '')
        + (', unstable_fits on' if args.unstable_fits else '')
        + (f', a prediction after every {args.every}. fix' if args.every else '')
        + '. NEES: 2 and 0.95 in the 95 % ellipse when honest.'
    )
    summary = []
    for case_name in args.cases:
        case, ci = CASES[case_name], list(CASES).index(case_name)
        per, t_flights, draw_of = [], [], []
        for seed in range(args.seed, args.seed + args.draws):
            rng = np.random.default_rng(seed * 1000 + ci)
            for k, r in enumerate(random_releases(rng, args.flights, case)):
                res, t_land = run_flight(
                    r, seed * 100000 + ci * 1000 + k, case, args.wind_sigma,
                    clutter=args.clutter, two_balls=args.two_balls, every=args.every,
                )
                per.append(res)
                t_flights.append(t_land)
                draw_of.append(seed)
        print(f'\ncase: {case_name}')
        print(
            f'{"lead [s]":>8} {"method":>9} {"n":>4} {"median [m]":>11} {"p95 [m]":>9} '
            f'{"|dt| med [s]":>13} {"|dt| p95 [s]":>13} {"failed":>7} {"NEES":>6} '
            f'{"in 95%":>7}'
        )
        for lead in LEADS:
            for m in methods:
                vals = [p[lead][m] for p in per if p[lead][m] is not None]
                failed = len(per) - len(vals)
                if not vals:
                    print(f'{lead:>8.1f} {m:>9} {0:>4} {"-":>11}')
                    continue
                err = np.array([v[0] for v in vals])
                dt = np.abs(np.array([v[1] for v in vals]))
                nees = np.array([v[2] for v in vals])
                consistency = (
                    f' {np.mean(nees):>6.2f} {np.mean(nees <= CHI2_2_95):>7.2f}'
                    if np.all(np.isfinite(nees))
                    else ''
                )
                print(
                    f'{lead:>8.1f} {m:>9} {len(vals):>4} {np.median(err):>11.3f} '
                    f'{np.percentile(err, 95):>9.3f} {np.median(dt):>13.4f} '
                    f'{np.percentile(dt, 95):>13.4f} {failed:>7}{consistency}'
                )
        summary += _summary_rows(case_name, per, np.array(t_flights), np.array(draw_of))
    print(
        '\ntracker per case (median of the per-draw medians [m] and their range; NEES mean; '
        'fraction in the 95 % ellipse; targets: NEES 1.5-3, >= 0.90 inside)'
    )
    print(f'{"case":>42} {"lead":>5} {"n":>4} {"median":>7} {"draw range":>15} {"NEES":>6} '
          f'{"in 95%":>7}')
    for row in summary:
        print(row)
    period = 1e3 / RATE
    times = time_tracker(
        random_releases(np.random.default_rng(args.seed), 20, CASES['defaults']), args.seed
    )
    print(
        f'\ntracker time per fix [ms] over {times["update wall"].size} fixes of 20 flights '
        f"(frame period {period:.2f} ms; cpu = this thread's CPU time, wall includes waiting "
        f'for a shared core)'
    )
    print(f'{"":>22} {"median":>8} {"p99":>8} {"max":>8} {"p99/period":>11} {"at 120 Hz":>10}')
    for key, ms in times.items():
        p99 = np.percentile(ms, 99)
        print(
            f'{key:>22} {np.median(ms):>8.3f} {p99:>8.3f} {ms.max():>8.3f} '
            f'{p99 / period:>11.3f} {p99 * 120.0 / 1e3:>10.3f}'
        )


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    # One section per kind of run: the plain cases, with the wind estimated, with clutter.
    pre = argparse.ArgumentParser(add_help=False)
    pre.add_argument('--wind-sigma', type=float, default=0.0)
    pre.add_argument('--gust-rate', type=float, default=-1.0)
    pre.add_argument('--gust-prior', type=float, default=0.0)
    pre.add_argument('--clutter', type=float, default=0.0)
    pre.add_argument('--two-balls', action='store_true')
    pre.add_argument('--cameras', action='store_true')
    pre.add_argument('--cases', nargs='*', default=[])
    pre.add_argument('--rigs', nargs='*', default=[])
    pre.add_argument('--unstable-fits', action='store_true')
    pre.add_argument('--every', type=int, default=0)
    pre.add_argument('--seed', type=int, default=1)
    flags, _ = pre.parse_known_args()
    field_only = bool(flags.cases) and all(c in FIELD_CASES for c in flags.cases)
    section = 'prediction' + (', field cases' if field_only else '') + ''.join(
        f', {name} {value:g}' for name, value in
        (('wind_sigma', flags.wind_sigma), ('gust_rate', flags.gust_rate),
         ('gust_prior', flags.gust_prior), ('clutter Hz', flags.clutter))
        if value > 0.0 or (name == 'gust_rate' and value == 0.0)
    ) + (', two balls' if flags.two_balls else '') + (', cameras' if flags.cameras else '') + (
        ', unstable_fits on' if flags.unstable_fits else '') + (
        f', a prediction every {flags.every} fixes' if flags.every > 0 else '') + (
        f', seed {flags.seed}' if flags.seed != 1 else '') + (
        f' ({", ".join(flags.rigs)})' if flags.cameras and flags.rigs else '')
    raise SystemExit(results.recorded(section, main))
