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
The tracker's CPU with ``unstable_fits`` off and on, driven as the node drives it (headless).

Each flight of bench/prediction_benchmark.py's cases (its generator, seeds and camera: 60 Hz,
the field cases' fixes and told covariances) is replayed into a fresh FlightTracker at its
defaults, once with ``unstable_fits`` False and once True: ``update`` at every fix and
``predict_landing`` after every ``--every``-th (2: 30 predictions/s at 60 Hz, the node's
``prediction_rate``). Per case and setting: the thread's CPU [s] per flight and per second of
flight (above 1: one core cannot keep up), per fix (update and any prediction after it) its
mean and p99 [ms], the worst single update and the worst update + prediction [ms] (how long
the node's callback blocks); and whether every prediction (landing point and covariance) is
bit-identical off and on (a case the setting must not touch).

    .venv/bin/python bench/tracker_cpu.py [--flights 3] [--seed 3] [--every 2]
        [--cases defaults 'rugby 60-600 rpm' ...]
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import time

from football_ros.estimation import FlightTracker, TrackerSettings
from football_ros.physics import Release
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
_benchmark = importlib.import_module('prediction_benchmark')  # its flights, camera and cases
CASES = _benchmark.CASES
DEFAULT_CASES = ('defaults', 'rugby 60-600 rpm', 'gust 2-8 m/s over 0.5-2 s',
                 'end over end 20-120 rpm', 'rugby 0-120 rpm')


def replay(fixes: list, case, unstable: bool, every: int) -> dict:
    """Replay one flight; CPU [s] per fix, the worst update [s] and the predictions made."""
    tracker = FlightTracker(TrackerSettings(noise=case.noise, ball=case.ball,
                                            unstable_fits=unstable))
    per_fix, worst_update, preds = [], 0.0, []
    for i, (o, cov) in enumerate(fixes):
        c0 = time.thread_time()
        tracker.update(o.stamp, o.position, covariance=cov)
        c1 = time.thread_time()
        pred = tracker.predict_landing() if i % every == 0 else None
        per_fix.append(time.thread_time() - c0)
        worst_update = max(worst_update, c1 - c0)
        if pred is not None:
            preds.append(np.concatenate([pred.position, pred.covariance.ravel()]))
    return {'cpu': np.array(per_fix), 'update': worst_update, 'preds': preds}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    ap.add_argument('--flights', type=int, default=3, help='flights per case')
    ap.add_argument('--seed', type=int, default=3, help="the benchmark's draw (its seeding)")
    ap.add_argument('--every', type=int, default=2, help='a prediction after every n-th fix')
    ap.add_argument('--cases', nargs='*', default=list(DEFAULT_CASES))
    args = ap.parse_args()
    unknown = sorted(set(args.cases) - set(CASES))
    if unknown or not (1 <= args.flights <= 100 and 1 <= args.every <= 100):
        ap.error(f'unknown case(s) {unknown}, or --flights / --every outside 1-100')
    warm = _benchmark.flight_fixes(Release(model='full'), 0, CASES['defaults'])[0]
    replay(warm, CASES['defaults'], True, args.every)  # the compiled kernels warmed
    print(f"{args.flights} flights a case, draw {args.seed} (prediction_benchmark's seeding), "
          f'a prediction after every {args.every}. fix; CPU of this thread; per fix: its update '
          'and the prediction after it')
    print(f'{"case":>26} {"unstable_fits":>13} {"fixes":>6} {"s/flight":>9} {"s/s flown":>10} '
          f'{"mean ms":>8} {"p99 ms":>8} {"worst update ms":>16} {"worst upd+pred ms":>18}')
    for name in args.cases:
        case, ci = CASES[name], list(CASES).index(name)
        releases = _benchmark.random_releases(np.random.default_rng(args.seed * 1000 + ci),
                                              args.flights, case)
        flights = [_benchmark.flight_fixes(r, args.seed * 100000 + ci * 1000 + k, case)[:2]
                   for k, r in enumerate(releases)]
        runs = {on: [replay(f, case, on, args.every) for f, _ in flights] for on in (False, True)}
        flown = sum(t for _, t in flights)
        for on, got in runs.items():
            cpu = np.concatenate([g['cpu'] for g in got])
            print(f'{name:>26} {"on" if on else "off":>13} {cpu.size:>6} '
                  f'{cpu.sum() / len(got):>9.2f} {cpu.sum() / flown:>10.2f} '
                  f'{cpu.mean() * 1e3:>8.1f} {np.percentile(cpu, 99) * 1e3:>8.1f} '
                  f'{max(g["update"] for g in got) * 1e3:>16.1f} {cpu.max() * 1e3:>18.1f}')
        same = all(len(a['preds']) == len(b['preds'])
                   and all(np.array_equal(p, q) for p, q in zip(a['preds'], b['preds']))
                   for a, b in zip(runs[False], runs[True]))
        print(f'{"":>26} predictions bit-identical off and on: {same}')


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('tracker CPU, unstable_fits off and on', main))
