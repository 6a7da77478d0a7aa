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
Start-up of the commands that neither integrate nor draw, against ``python -c "import numpy"``.

    .venv/bin/python bench/startup_benchmark.py [--repeat 9]

Every contender is a fresh process of this interpreter (the same venv, so the same site
start-up), run in turn ``--repeat`` times; the table gives the median and the best wall time
and the ratio of the medians to ``import numpy`` measured in the same run. Target (issue 12.3):
``football-ros modes`` and ``--help`` <= 2x ``import numpy``. Also listed: which of numba,
scipy, matplotlib and rclpy each command imported.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import statistics
import subprocess
import sys
import time

HEAVY = ('numba', 'scipy', 'matplotlib', 'rclpy')
CODE = (
    'import sys\nfrom football_ros.cli import main\ntry:\n    main({argv!r})\n'
    'except SystemExit:\n    pass\n'
    "mods = sorted({{m.split('.')[0] for m in sys.modules}} & set({heavy!r}))\n"
    "print('HEAVY', ' '.join(mods) or '-', file=sys.stderr)\n"
)


def contenders() -> list[tuple[str, list[str], str | None]]:
    """(name, command, probe code or None)."""
    py = sys.executable
    script = Path(py).with_name('football-ros')
    rows = [
        ('python -c pass', [py, '-c', 'pass'], None),
        ('python -c "import numpy" (baseline)', [py, '-c', 'import numpy'], None),
    ]
    for argv in (['--help'], ['modes'], ['modes', '--json'], ['montecarlo', '--help']):
        rows.append(
            (
                f'football-ros {" ".join(argv)}',
                [py, '-c', CODE.format(argv=argv, heavy=HEAVY)],
                'probe',
            )
        )
    if script.exists():
        rows.append(('football-ros modes (console script)', [str(script), 'modes'], None))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--repeat', type=int, default=9, help='runs of each contender')
    args = parser.parse_args()
    rows = contenders()
    times: dict[str, list[float]] = {name: [] for name, _, _ in rows}
    heavy: dict[str, str] = {}
    env = dict(os.environ)
    for _ in range(args.repeat):
        for name, cmd, probe in rows:
            start = time.perf_counter()
            proc = subprocess.run(
                cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env
            )
            times[name].append(time.perf_counter() - start)
            if proc.returncode != 0:
                raise SystemExit(f'{name} failed: {proc.stderr}')
            if probe:
                heavy[name] = proc.stderr.strip().split('HEAVY ', 1)[-1]
    base = statistics.median(times['python -c "import numpy" (baseline)'])
    print(
        f'\nstart-up, {args.repeat} runs each, {os.cpu_count()} cores '
        '(median and best wall time)\n'
    )
    print(f'{"command":<40}{"median [s]":>11}{"best [s]":>10}{"x numpy":>9}  heavy imports')
    for name, _, _ in rows:
        med, best = statistics.median(times[name]), min(times[name])
        print(f'{name:<40}{med:>11.3f}{best:>10.3f}{med / base:>9.2f}  {heavy.get(name, "")}')
    print('\ntarget: football-ros modes and --help <= 2.00 x numpy')


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('start-up', main))
