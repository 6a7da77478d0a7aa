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
The Foxglove viewer (football-ros view) beside a simulator flying many balls.

    .venv/bin/python bench/view_benchmark.py [--balls 10] [--rate 100] [--seconds 5]
        [--stall 10] [--draws 3]

The simulator (a subprocess, as bench/entities_benchmark.py starts it) flies ``--balls``
spawned balls at ``--rate`` Hz (12 s lobs thrown with SetEntityState, thrown again for each
window). Per draw, windows of ``--seconds``, the simulator's CPU (user + system) and late
ticks (its /diagnostics: overruns + skipped) in each:

- none: nobody subscribed to the balls' topics (the simulator skips them);
- ros: a plain rclpy subscriber (this process) on every ball's pose and odom and /tf: the
  baseline the viewer is compared with;
- view: the viewer node (a subprocess) with one Foxglove client (a subprocess) subscribed to
  the same topics and the scene. The client takes the latency of each pose message from the
  simulator's stamp (wall clock) to its receipt; the plain rclpy subscriber's latency of the
  same kind is measured in the ros window (the baseline);
- stalled: the same client stops reading for ``--stall`` s (its socket fills, the viewer's
  queue for it overflows): the simulator's late ticks and the viewer's memory (VmRSS before,
  at the end of the stall, and after the client reads again).

Targets (issue 35): latency p95 <= 20 ms at 100 Hz with 10 balls; simulator CPU with the
viewer <= 1.2 x without; late ticks while stalled no worse than without; the viewer's memory
bounded.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(100 + os.getpid() % 50))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / 'test'))


def client_main(url: str, seconds: float, stall: float, topics: list[str]) -> None:
    """Run the Foxglove client subprocess: subscribe, read, stall, read; print JSON lines."""
    from foxglove_client import FoxgloveClient

    client = FoxgloveClient(url, decode=False)
    client.wait_for(lambda: all(t in client.channels for t in topics), 60.0, 'the channels')
    client.subscribe(*topics)
    client.poll(1.0)
    client.messages.clear()
    print(json.dumps({'phase': 'reading'}), flush=True)
    client.poll(seconds)
    latencies = [  # [ms]: stamp -> receipt, stamp -> handed to the server (the log time)
        ((received - _stamp_ns(payload)) / 1e6, (logged - _stamp_ns(payload)) / 1e6)
        for topic, items in client.messages.items() if topic.endswith('/pose')
        for received, logged, payload in items
    ]
    count = sum(len(v) for v in client.messages.values())
    print(json.dumps({'phase': 'stalling', 'latencies': latencies, 'count': count}), flush=True)
    time.sleep(stall)  # reads nothing: the socket and the client's small queue fill
    print(json.dumps({'phase': 'reading again'}), flush=True)
    client.messages.clear()
    client.poll(3.0)
    print(json.dumps({'phase': 'done', 'count': sum(len(v) for v in client.messages.values())}),
          flush=True)
    client.close()


def _stamp_ns(payload: bytes) -> int:
    """Header stamp [ns] of a CDR message that starts with a std_msgs/Header."""
    sec, nsec = struct.unpack_from('<iI', payload, 4)
    return sec * 1_000_000_000 + nsec


def vm_rss_mb(pid: int) -> float:
    """Resident memory [MB] of process ``pid``."""
    text = Path(f'/proc/{pid}/status').read_text()
    return int(re.search(r'VmRSS:\s+(\d+)', text).group(1)) / 1024


def percentile(values: list[float], q: float) -> float:
    """Return the nearest-rank percentile ``q`` of ``values`` (NaN when empty)."""
    if not values:
        return float('nan')
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(q / 100 * (len(ordered) - 1))))]


def main() -> int:
    """Run the draws and print the tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--balls', type=int, default=10)
    parser.add_argument('--rate', type=float, default=100.0)
    parser.add_argument('--seconds', type=float, default=5.0)
    parser.add_argument('--stall', type=float, default=10.0)
    parser.add_argument('--draws', type=int, default=3)
    args = parser.parse_args()

    from entities_benchmark import Bench, cpu_seconds, LOCK_STEP_LOB, Simulator
    from football_ros.nodes import qos
    from geometry_msgs.msg import PoseStamped
    from nav_msgs.msg import Odometry
    from simulation_interfaces.msg import SimulationState
    from tf2_msgs.msg import TFMessage

    log_dir = Path(tempfile.mkdtemp(prefix='view_bench_'))
    sim = Simulator(args.rate, log_dir)
    bench = Bench()
    names = [f'b{k}' for k in range(args.balls)]
    topics = ['/tf', '/football/scene'] + [
        f'/football/{n}/{leaf}' for n in names for leaf in ('pose', 'odom')]

    def throw() -> None:
        bench.reset()
        bench.set_state(SimulationState.STATE_PAUSED)
        bench.spawn_and_throw(args.balls, LOCK_STEP_LOB)
        bench.spin(1.0)
        bench.set_state(SimulationState.STATE_PLAYING)
        bench.spin(0.5)

    def measure(seconds: float) -> tuple[float, int]:
        """Return the simulator's CPU seconds and late ticks (overruns + skipped) in a window."""
        late0, skipped0 = bench.late_ticks()
        cpu0 = cpu_seconds(sim.proc.pid)
        bench.spin(seconds)
        cpu = cpu_seconds(sim.proc.pid) - cpu0
        late1, skipped1 = bench.late_ticks()
        return cpu, (late1 - late0) + (skipped1 - skipped0)

    rows = []
    load = [os.getloadavg()]  # the machine's load (1, 5, 15 min) at the start and the end
    try:
        for draw in range(args.draws):
            row = {}
            throw()
            row['none'] = measure(args.seconds)
            # The baseline: a plain rclpy subscriber on the same topics, its latencies.
            throw()
            latencies = []

            def take(data: bytes) -> None:
                latencies.append((time.time_ns() - _stamp_ns(data)) / 1e6)

            subs = [bench.node.create_subscription(cls, qos.entity_topic(n, leaf),
                                                   take if leaf == 'pose' else (lambda _d: None),
                                                   qos.STATE, raw=True)
                    for n in names for cls, leaf in ((PoseStamped, 'pose'), (Odometry, 'odom'))]
            subs.append(bench.node.create_subscription(TFMessage, qos.TF, lambda _d: None,
                                                       qos.TF_QOS, raw=True))
            bench.spin(1.0)
            latencies.clear()
            row['ros'] = measure(args.seconds)
            row['ros_latency'] = list(latencies)
            for sub in subs:
                bench.node.destroy_subscription(sub)
            # The viewer and its client.
            view_log = log_dir / f'view_{draw}.log'
            view = subprocess.Popen(
                [sys.executable, '-m', 'football_ros.cli', 'view', '--port', '0'],
                stdout=open(view_log, 'w'), stderr=subprocess.STDOUT, cwd=REPO,
                env=dict(os.environ, PYTHONPATH=str(REPO)))
            while not re.search(r'ws://[0-9.]+:\d+', view_log.read_text()):
                if view.poll() is not None:
                    raise SystemExit(f'view did not start:\n{view_log.read_text()}')
                time.sleep(0.1)
            url = re.search(r'ws://[0-9.]+:\d+', view_log.read_text()).group(0)
            throw()
            client = subprocess.Popen(
                [sys.executable, __file__, '--client', url, str(args.seconds), str(args.stall),
                 *topics], stdout=subprocess.PIPE, text=True, cwd=REPO,
                env=dict(os.environ, PYTHONPATH=str(REPO)))
            assert json.loads(client.stdout.readline())['phase'] == 'reading'
            row['view'] = measure(args.seconds)
            stalling = json.loads(client.stdout.readline())
            row['view_latency'], row['view_count'] = stalling['latencies'], stalling['count']
            rss0 = vm_rss_mb(view.pid)
            row['stalled'] = measure(min(args.stall, 10.0) - 0.5)
            rss1 = vm_rss_mb(view.pid)
            assert json.loads(client.stdout.readline())['phase'] == 'reading again'
            row['after_count'] = json.loads(client.stdout.readline())['count']
            row['rss'] = (rss0, rss1, vm_rss_mb(view.pid))
            client.wait(timeout=30)
            bench.spin(1.5)
            row['overflows'] = _overflows(bench)
            view.send_signal(2)
            row['view_exit'] = view.wait(timeout=20)
            rows.append(row)
    finally:
        sim.stop()
    load.append(os.getloadavg())
    _report(args, rows, load)
    return 0


def _overflows(bench) -> str:
    """Return the viewer's 'viewer queue overflows' from /diagnostics (its last status)."""
    from diagnostic_msgs.msg import DiagnosticArray
    from football_ros.nodes import qos

    found = {}

    def take(msg) -> None:
        for status in msg.status:
            if status.name.endswith('football_view'):
                found.update({kv.key: kv.value for kv in status.values})

    sub = bench.node.create_subscription(DiagnosticArray, qos.DIAGNOSTICS, take,
                                         qos.DIAGNOSTICS_QOS)
    end = time.monotonic() + 5.0
    while 'viewer queue overflows' not in found and time.monotonic() < end:
        bench.spin(0.1)
    bench.node.destroy_subscription(sub)
    return found.get('viewer queue overflows', '?')


def _report(args, rows, load) -> None:
    print(f'{args.balls} balls at {args.rate:g} Hz, {args.seconds:g} s windows, '
          f'{len(rows)} draws; stall {args.stall:g} s. CPU = simulator process (user + system) '
          '[s per window]; late = its overruns + skipped ticks in the window.')
    print('load average (1, 5, 15 min) at the start ' + ', '.join(f'{v:.2f}' for v in load[0])
          + '; at the end ' + ', '.join(f'{v:.2f}' for v in load[1]) + '\n')
    print('draw | CPU none | CPU ros | CPU view | view/none | view/ros | late none | late ros '
          '| late view | late stalled')
    for k, r in enumerate(rows):
        print(f'{k:4d} | {r["none"][0]:8.2f} | {r["ros"][0]:7.2f} | {r["view"][0]:8.2f} | '
              f'{r["view"][0] / r["none"][0]:9.2f} | {r["view"][0] / r["ros"][0]:8.2f} | '
              f'{r["none"][1]:9d} | {r["ros"][1]:8d} | {r["view"][1]:9d} | {r["stalled"][1]:12d}')
    view_ratio = statistics.median(r['view'][0] / r['ros'][0] for r in rows)
    none_ratio = statistics.median(r['view'][0] / r['none'][0] for r in rows)
    print(f'\nmedian CPU ratio view/ros {view_ratio:.2f} (target <= 1.2), view/none '
          f'{none_ratio:.2f}')
    print('\nlatency [ms] of the pose messages, all draws (stamp = the simulator wall clock '
          'at publishing):')
    print('from stamp to                                  |     n |   p50 |   p95 |   max')
    for name, values in (
        ('rclpy subscriber receipt (baseline)', [v for r in rows for v in r['ros_latency']]),
        ('Foxglove client receipt', [v[0] for r in rows for v in r['view_latency']]),
        ('  of which: handed to the server (view node)', [v[1] for r in rows
                                                          for v in r['view_latency']]),
        ('  server to client (handed -> receipt)', [v[0] - v[1] for r in rows
                                                    for v in r['view_latency']]),
    ):
        print(f'{name:46s} | {len(values):5d} | {percentile(values, 50):5.2f} | '
              f'{percentile(values, 95):5.2f} | {max(values, default=float("nan")):5.1f}')
    expected = args.balls * args.rate * args.seconds
    print(f'\npose messages per window at the client: '
          f'{[len(r["view_latency"]) for r in rows]} of {expected:.0f} published')
    print('\nstalled viewer: viewer VmRSS [MB] before / end of stall / after; queue overflows '
          'reported; messages read in 3 s after the stall; exit code after SIGINT')
    for k, r in enumerate(rows):
        b, s, a = r['rss']
        print(f'draw {k}: {b:.0f} / {s:.0f} / {a:.0f} MB; overflows {r["overflows"]}; '
              f'{r["after_count"]} read after; exit {r["view_exit"]}')


if __name__ == '__main__':
    if len(sys.argv) > 1 and sys.argv[1] == '--client':
        client_main(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), sys.argv[5:])
        raise SystemExit(0)
    from results import recorded

    raise SystemExit(recorded('view', main))
