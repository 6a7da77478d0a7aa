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
``football-ros fit`` against flights of known coefficients (headless).

Truth: passes flown by the package's simulator (``Flight``, RK4 at 1 ms) with the American
football's default coefficients, and, in the same run, with a known different set (C_D0 0.08,
C_D2 0.45, C_Lalpha 0.25, C_Malpha 0.25); fixes at 100 Hz from release to landing with 2 cm
Gaussian noise per axis (and, where said, the spin axis with 1 deg per component). A pass:
speed U(20, 28) m/s, elevation U(15, 35) deg, azimuth U(-15, 15) deg, released at 1.8 m,
600 rpm (the fit's spin, fixed), axis off the velocity by N(0, 2 deg) per angle, no axis rate.
The fit is told the truth's values of what it does not free (C_D2 and, unless freed, C_Malpha:
the lift acts on the yaw of repose C_Malpha sets, so a wrong held value biases C_Lalpha) and
starts the freed ones at the package's defaults; the release rates are its default ('auto').

Cases (each ``--trials`` trials of ``--passes`` passes):
- positions: C_D0 and C_Lalpha freed; targets: median relative error <= 5 % and <= 10 %;
- axes: positions and axes, C_D0, C_Lalpha and C_Malpha freed; C_Malpha <= 5 %;
- short pass: one pass under 1 s (speed U(12, 14) m/s, elevation U(3, 8) deg), C_D0,
  C_Lalpha and C_Npalpha freed: Magnus cannot be identified from it (its interval at the
  truth, from the noise-free information, is wider than its physical range in every trial):
  flagged in >= 95 % of trials.
Coverage: the share of trials whose 95 % interval holds the truth, per coefficient reported
identifiable (target 90-98 %), with its Wilson 95 % interval. Timing: one 3 s flight fitted
(C_D0, C_Lalpha), with and without the profile check, median of ``--draws``; the baseline is
the same flight simulated once (``Flight.simulate``), in the same run.

    .venv/bin/python bench/fit_benchmark.py [--part timing accuracy coverage short]
        [--trials 50] [--passes 20] [--coverage-trials 200] [--short-trials 100] [--draws 5]
        [--seed 0] [--no-record]

Each run records one section of bench/RESULTS.md named after its parts ("fit (timing,
short)"), so that parts may run in parallel processes.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import math
import os
import sys
import time

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')  # one core: before numpy loads

from football_ros.identification import fit, FitSettings, Track  # noqa: E402
from football_ros.physics import Flight, get_preset, Release  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results import recorded  # noqa: E402

NOISE = 0.02
AXIS_NOISE = math.radians(1.0)
RATE = 100.0
SETS = {
    'defaults': ({}, {}),
    'different': ({'c_d0': 0.08, 'c_d2': 0.45, 'c_l_alpha': 0.25}, {'c_m_alpha': 0.25}),
}
"""Truth coefficient sets: (aero settings, ball overrides)."""
TARGETS = {'c_d0': 0.05, 'c_l_alpha': 0.10, 'c_m_alpha': 0.05}


def truth_of(name: str, aero: dict, ball: dict) -> float:
    """Return the truth's value of coefficient ``name``."""
    defaults = {'c_d0': 0.055, 'c_d2': 0.30, 'c_l_alpha': 0.40, 'c_n_p_alpha': 0.0,
                'c_m_alpha': get_preset('american').c_m_alpha}
    return {**defaults, **aero, **ball}[name]


def pass_track(rng, aero: dict, ball: dict, axes: bool, short: bool = False,
               clean: bool = False):
    """One simulated pass with noisy fixes (the module docstring); ``clean``: also without."""
    speed = rng.uniform(12.0, 14.0) if short else rng.uniform(20.0, 28.0)
    elevation = rng.uniform(3.0, 8.0) if short else rng.uniform(15.0, 35.0)
    release = Release(
        ball='american', speed=speed, elevation_deg=elevation,
        azimuth_deg=rng.uniform(-15.0, 15.0), spin_rpm=600.0,
        alpha0_deg=rng.normal(0.0, 2.0), beta0_deg=rng.normal(0.0, 2.0),
        position=(0.0, 0.0, 1.8), model='full', aero=aero, ball_params=ball)
    trajectory = Flight.from_release(release).simulate(rate=RATE, duration=10.0)
    n = trajectory.times.size - 1 if trajectory.landed else trajectory.times.size
    t = trajectory.times[:n]
    seen = None
    if axes:
        seen = trajectory.axes[:n] + rng.normal(0.0, AXIS_NOISE, (n, 3))
        seen /= np.linalg.norm(seen, axis=1)[:, None]
    noisy = Track(t, trajectory.positions[:n] + rng.normal(0.0, NOISE, (n, 3)), axes=seen)
    return (noisy, Track(t, trajectory.positions[:n])) if clean else noisy


def wilson(k: int, n: int) -> tuple[float, float]:
    """Wilson 95 % interval of a proportion k / n."""
    if n == 0:
        return math.nan, math.nan
    z = 1.959963984540054
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def run_case(label, free, axes, trials, passes, seed, sets=tuple(SETS), short=False):
    """
    Fit ``trials`` draws of each truth set: errors, coverage, flags.

    A short pass is also fitted without noise (sigma given): a coefficient whose interval at
    the truth is wider than its physical range cannot be identified; ``flagged`` counts the
    noisy fits that say so among those trials.
    """
    from football_ros.identification.coefficients import COEFFICIENTS
    from football_ros.identification.uncertainty import Z95

    rows = []
    for set_name in sets:
        aero, ball = SETS[set_name]
        rng = np.random.default_rng(seed)
        errors = {n: [] for n in free}
        covered = {n: [0, 0] for n in free}
        flagged = {n: [0, 0] for n in free}
        seconds = []
        for _ in range(trials):
            drawn = [pass_track(rng, aero, ball, axes, short, clean=True) for _ in range(passes)]
            tracks = [noisy for noisy, _ in drawn]
            settings = FitSettings(  # told the truth's fixed values, not its freed ones
                get_preset('american', {k: v for k, v in ball.items() if k not in free}),
                free=free, aero=_aero({k: v for k, v in aero.items() if k not in free}))
            start = time.process_time()
            result = fit(tracks, settings)
            seconds.append(time.process_time() - start)
            bound = None
            if short:
                bound = fit([clean for _, clean in drawn],
                            replace(settings, noise=NOISE, profile=False)).coefficients
            for name in free:
                c = result.coefficients[name]
                truth = truth_of(name, aero, ball)
                if bound is not None:
                    lo, hi = COEFFICIENTS[name].physical
                    sigma = bound[name].sigma
                    if sigma is None or 2.0 * Z95 * sigma > hi - lo:
                        flagged[name][1] += 1
                        flagged[name][0] += int(not c.identifiable)
                if not c.identifiable:
                    continue
                if truth != 0.0:
                    errors[name].append(abs(c.value - truth) / abs(truth))
                covered[name][1] += 1
                covered[name][0] += int(c.ci95[0] <= truth <= c.ci95[1])
        for name in free:
            k, n = covered[name]
            lo, hi = wilson(k, n)
            med = float(np.median(errors[name])) if errors[name] else math.nan
            rows.append((label, set_name, name, truth_of(name, aero, ball), med,
                         TARGETS.get(name) if not short and passes > 2 else None, n,
                         k / n if n else math.nan, lo, hi, flagged[name],
                         float(np.median(seconds))))
    return rows


def _aero(mapping):
    from football_ros.physics.aero import AeroModel

    return AeroModel.from_mapping(mapping)


def timing(draws: int, seed: int) -> list[tuple]:
    """
    One 3 s flight: simulate (baseline), fit with and without the profile check.

    Per draw: simulate's CPU time, the flight's duration, then CPU and wall time of each fit.
    CPU time (this process's) is what one core spends: on a shared machine the wall time also
    holds the waits for the core.
    """
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(draws):
        release = Release(ball='american', speed=27.0, elevation_deg=33.0, spin_rpm=600.0,
                          alpha0_deg=rng.normal(0.0, 2.0), beta0_deg=rng.normal(0.0, 2.0),
                          position=(0.0, 0.0, 1.8), model='full')
        start = time.process_time()
        trajectory = Flight.from_release(release).simulate(rate=RATE, duration=10.0)
        simulate = time.process_time() - start
        n = trajectory.times.size - 1
        track = Track(trajectory.times[:n],
                      trajectory.positions[:n] + rng.normal(0.0, NOISE, (n, 3)))
        row = [simulate, float(trajectory.times[n])]
        for profile in (False, True):
            start, wall = time.process_time(), time.perf_counter()
            fit([track], FitSettings(get_preset('american'), profile=profile))
            row += [time.process_time() - start, time.perf_counter() - wall]
        out.append(row)
    return out


PARTS = ('timing', 'accuracy', 'coverage', 'short')


def parse(known: bool = False) -> argparse.Namespace:
    """
    Return the options (``--part``: which parts, each recorded as its own section).

    ``known``: ignore the others (``--no-record``, before :func:`recorded` removes it).
    """
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument('--part', nargs='*', choices=PARTS, default=list(PARTS),
                    help='parts to run (default all); each is its own section of RESULTS.md')
    ap.add_argument('--trials', type=int, default=50, help='trials per case and truth set')
    ap.add_argument('--passes', type=int, default=20, help='passes per trial')
    ap.add_argument('--short-trials', type=int, default=100, help='trials of the short pass')
    ap.add_argument('--coverage-trials', type=int, default=200,
                    help='trials of the coverage cases (2 passes each)')
    ap.add_argument('--draws', type=int, default=5, help='timing draws')
    ap.add_argument('--seed', type=int, default=0)
    return ap.parse_known_args()[0] if known else ap.parse_args()


def main() -> int:
    args = parse()
    # Compile (or load) the kernels outside the timings.
    fit([pass_track(np.random.default_rng(99), {}, {}, False)],
        FitSettings(get_preset('american')))
    if 'timing' in args.part:
        print_timing(args)
    start = time.process_time()
    cases = {
        'accuracy': [('positions', ('c_d0', 'c_l_alpha'), False, args.trials, args.passes,
                      args.seed, tuple(SETS), False),
                     ('axes', ('c_d0', 'c_l_alpha', 'c_m_alpha'), True, args.trials,
                      args.passes, args.seed + 1, tuple(SETS), False)],
        'coverage': [('coverage', ('c_d0', 'c_l_alpha'), False, args.coverage_trials, 2,
                      args.seed + 3, ('defaults',), False),
                     ('cov. axes', ('c_d0', 'c_l_alpha', 'c_m_alpha'), True,
                      args.coverage_trials, 2, args.seed + 4, ('defaults',), False)],
        'short': [('short pass', ('c_d0', 'c_l_alpha', 'c_n_p_alpha'), False,
                   args.short_trials, 1, args.seed + 2, ('defaults',), True)],
    }
    chosen = [case for part in PARTS[1:] if part in args.part for case in cases[part]]
    if not chosen:
        return 0
    print(f'{args.trials} trials of {args.passes} passes per accuracy case and truth set, '
          f'{args.coverage_trials} trials of 2 passes per coverage case, {args.short_trials} '
          'of one short pass; n = trials reporting the coefficient identifiable, coverage = '
          'share of them whose 95 % interval holds the truth (Wilson 95 %); flagged = not '
          'identifiable among the trials where the truth cannot be identified (k/m); s/fit = '
          'median CPU s of a fit')
    print(f"{'case':<11}{'truth set':<11}{'coefficient':<13}{'truth':>7}{'median err':>11}"
          f"{'target':>8}{'n':>5}{'coverage':>9}{'  (95 %)':<15}{'flagged':>12}{'s/fit':>7}",
          flush=True)
    for label, free, axes, trials, passes, seed, sets, short in chosen:
        for (label, set_name, name, truth, med_err, target, n, cov, lo, hi, flag,
             sec) in run_case(label, free, axes, trials, passes, seed, sets, short):
            err = f'{med_err * 100:.1f} %' if math.isfinite(med_err) else '-'
            tgt = f'{target * 100:.0f} %' if target else '-'
            cov_text = f'{cov * 100:.0f} %' if n else '-'
            band = f' [{lo * 100:.0f}, {hi * 100:.0f}]' if n else ''
            flags = f'{flag[0]}/{flag[1]}' if flag[1] else '-'
            print(f'{label:<11}{set_name:<11}{name:<13}{truth:>7.3g}{err:>11}{tgt:>8}{n:>5}'
                  f'{cov_text:>9}{band:<15}{flags:>12}{sec:>7.1f}', flush=True)
    print(f'({time.process_time() - start:.0f} s CPU in all)')
    return 0


def print_timing(args: argparse.Namespace) -> None:
    """Print the timing table (the module docstring)."""
    times = np.array(timing(args.draws, args.seed))
    med = np.median(times, axis=0)
    print(f'Timing, one flight of {med[1]:.2f} s at 100 Hz, 2 cm, C_D0 and C_Lalpha freed '
          f'(median of {args.draws} draws, one process, numba kernels loaded; CPU time of '
          f'this process, one thread; wall time beside it, load average '
          f'{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores):')
    print(f'  simulate the flight (baseline)      {med[0] * 1e3:8.1f} ms CPU')
    print(f'  fit, Jacobian intervals             {med[2] * 1e3:8.1f} ms CPU '
          f'({med[2] / med[0]:.0f} x the baseline; wall {med[3] * 1e3:.0f} ms)')
    print(f'  fit, intervals checked by profile   {med[4] * 1e3:8.1f} ms CPU '
          f'({med[4] / med[0]:.0f} x the baseline; wall {med[5] * 1e3:.0f} ms; '
          'target < 1000 ms)', flush=True)


if __name__ == '__main__':
    sys.exit(recorded(f"fit ({', '.join(parse(known=True).part)})", main))
