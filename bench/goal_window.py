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
SimulateSteps goals in a row: the cost of a goal after many others.

    .venv/bin/python bench/goal_window.py [--draws 2] [--batches 15] [--goals 100]

The simulator (paused, one ball in the air) gets ``--batches`` x ``--goals`` SimulateSteps
goals of one step, one after the other from one action client, with its
``goal_result_timeout`` at 5 s and at 900 s (its default, rclpy's), in turn (``--draws``
times each). Every goal status message lists every goal whose result is still kept, so with
900 s the status messages grow with the run. Cells: the simulator's CPU [ms] per goal (its process,
/proc) and the client's wall time [ms] per goal, per batch.
"""

from __future__ import annotations

import argparse
from pathlib import Path
import statistics
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
import core_benchmark as cb  # noqa: E402
import entities_benchmark as eb  # noqa: E402
from football_ros.nodes.simulator import PARAMETERS  # noqa: E402
from results import recorded  # noqa: E402
from simulation_interfaces.msg import SimulationState  # noqa: E402

TIMEOUTS = (5.0, next(p.default for p in PARAMETERS if p.name == 'goal_result_timeout'))


def goals_in_a_row(owner: eb.Bench, tmp: Path, timeout: float, batches: int,
                   goals: int) -> list[tuple]:
    """(CPU ms per goal, wall ms per goal) of each batch, a fresh simulator with ``timeout``."""
    sim = cb.start([sys.executable, '-m', 'football_ros.cli', 'simulator', '--ros-args',
                    '-p', 'marker_rate:=0.0', '-p', f'goal_result_timeout:={timeout}'],
                   tmp / f'simulator-{timeout:g}.log')
    bench = eb.Bench(share=owner)  # fresh clients: none left listening to an earlier server
    try:
        bench.set_state(SimulationState.STATE_PAUSED)
        bench.spawn_and_throw(1, eb.LOCK_STEP_LOB)
        rows = []
        for _ in range(batches):
            cpu, wall = eb.cpu_ns(sim.pid), time.monotonic()
            for _ in range(goals):
                bench.simulate_steps(1)
            rows.append(((eb.cpu_ns(sim.pid) - cpu) * 1e-6 / goals,
                         (time.monotonic() - wall) * 1e3 / goals))
        return rows
    finally:
        if bench.action is not None:
            bench.action.destroy()
        for client in bench.clients.values():
            bench.node.destroy_client(client)
        cb.stop(sim)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--draws', type=int, default=2)
    parser.add_argument('--batches', type=int, default=15)
    parser.add_argument('--goals', type=int, default=100)
    args = parser.parse_args(argv)
    if min(args.draws, args.batches, args.goals) < 1:
        parser.error('--draws, --batches and --goals must be >= 1')
    runs = {timeout: [] for timeout in TIMEOUTS}
    owner = eb.Bench()
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.draws):
            for timeout in runs:
                runs[timeout].append(goals_in_a_row(owner, Path(tmp), timeout, args.batches,
                                                    args.goals))
    print(f'{args.batches} batches of {args.goals} SimulateSteps goals of 1 step in a row, one '
          f'action client; cells: draw 1 / 2 / ...; the simulator CPU ms per goal, the '
          'client wall ms per goal')
    print('| goals before the batch | ' + ' | '.join(
        f'goal_result_timeout {t:g} s: CPU ms | wall ms' for t in runs) + ' |')
    print('|---|' + '---|---|' * len(runs))
    for b in range(args.batches):
        cells = []
        for draws in runs.values():
            cells.append(' / '.join(f'{d[b][0]:.2f}' for d in draws))
            cells.append(' / '.join(f'{d[b][1]:.1f}' for d in draws))
        print(f'| {b * args.goals} | ' + ' | '.join(cells) + ' |')
    for timeout, draws in runs.items():
        last = [d[-1][0] / d[0][0] for d in draws]
        print(f'goal_result_timeout {timeout:g} s: the last batch CPU per goal / the first '
              f"batch's: {' / '.join(f'{x:.2f}' for x in last)} "
              f'(median {statistics.median(last):.2f})')
    return 0


if __name__ == '__main__':
    raise SystemExit(recorded('SimulateSteps goals in a row', main))
