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
Simulator node at a high publish rate vs a bare rclpy publisher, measured in the same run.

    .venv/bin/python bench/node_benchmark.py [--rate 1000] [--seconds 60] [--rounds 4]

For each publisher process, a subscriber in this (other) process records the arrival time of
every football/pose message for ``--seconds`` in total, split into ``--rounds`` alternating
segments (simulator, bare, simulator, bare, ...) so that both see the same drift of the load
of a shared machine; jitter is pooled over the segments (no interval spans two segments).
Reported: messages received and missed (gaps in the 1/rate stamp sequence), the
inter-arrival jitter |dt - 1/rate| (p50, p99, max), the publisher's CPU use, and for the
simulator its own overrun count from /diagnostics. The simulator is kept flying by a new
flight order every 2.5 s (replace policy).
Target (issue 12.4): 0 missed ticks, jitter p99 and max no worse than the bare publisher.

The bare publisher (bench/bare_publisher.py) publishes what the simulator publishes with its
default parameters: the six state messages and /tf every tick, markers at 30 Hz.

Where the simulator's time goes (py-spy record --threads on the simulator): every state
message is built and published by the pacing thread alone, most of it in rclpy's
Publisher.publish (the same work the bare publisher does); each tick integrates the next tick's
sample after publishing, so the state leaves at its deadline whatever the integration costs.
The figures of the last run: bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import signal
import subprocess
import sys
import threading
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from football_ros.nodes import qos  # noqa: E402
from football_ros.physics import Release  # noqa: E402
from football_ros.requests import FlightOrder  # noqa: E402
from geometry_msgs.msg import PoseStamped  # noqa: E402
import numpy as np  # noqa: E402
import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from std_msgs.msg import String  # noqa: E402

HERE = Path(__file__).resolve().parent
TICKS = os.sysconf('SC_CLK_TCK')


def cpu_seconds(pid: int) -> float:
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


class Probe:
    """A subscriber that records arrival times and stamps."""

    def __init__(self) -> None:
        self.node = rclpy.create_node('bench_probe')
        self.arrivals: list[int] = []
        self.stamps: list[int] = []
        self.overruns = 0
        self.recording = False
        self.node.create_subscription(PoseStamped, qos.POSE, self._on_pose, qos.STATE)
        self.node.create_subscription(
            DiagnosticArray, qos.DIAGNOSTICS, self._on_diag, qos.DIAGNOSTICS_QOS
        )
        self.orders = self.node.create_publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def _on_pose(self, msg) -> None:
        if self.recording:
            self.arrivals.append(time.monotonic_ns())
            self.stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)

    def _on_diag(self, msg) -> None:
        for status in msg.status:
            for kv in status.values:
                if kv.key == 'overruns':
                    self.overruns = int(kv.value)

    def measure(self, pid: int, seconds: float, rate: float, keep_flying: bool) -> dict:
        deadline = time.monotonic() + 30
        while self.node.count_publishers(qos.POSE) == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        if keep_flying:
            while self.orders.get_subscription_count() == 0:
                time.sleep(0.05)
        order = String(data=FlightOrder.from_release('bench', Release()).to_json())
        if keep_flying:
            self.orders.publish(order)
        time.sleep(2.0)  # settle
        overruns0, cpu0 = self.overruns, cpu_seconds(pid)
        self.arrivals.clear()
        self.stamps.clear()
        self.recording = True
        start = time.monotonic()
        next_order = start
        while time.monotonic() - start < seconds:
            if keep_flying and time.monotonic() >= next_order:
                self.orders.publish(order)
                next_order += 2.5
            time.sleep(0.05)
        self.recording = False
        cpu = cpu_seconds(pid) - cpu0
        arrivals = np.array(self.arrivals, dtype=np.int64)
        stamps = np.array(self.stamps, dtype=np.int64)
        period = 1e9 / rate
        jitter = np.abs(np.diff(arrivals) - period) / 1e6
        gaps = np.diff(stamps)
        missed = int(np.sum(np.maximum(np.round(gaps / period) - 1, 0))) if keep_flying else None
        if missed:
            where = np.nonzero(np.round(gaps / period) > 1)[0]
            print(f'stamp gaps: {[(int(i), int(gaps[i])) for i in where[:10]]} of {len(stamps)}')
        return {
            'received': len(arrivals),
            'expected': int(seconds * rate),
            'missed': missed,
            'jitter': jitter,
            'cpu_s': cpu,
            'seconds': seconds,
            'overruns': self.overruns - overruns0 if keep_flying else None,
        }


def pooled(parts: list[dict]) -> dict:
    """One result from the rounds of one publisher."""
    jitter = np.concatenate([p['jitter'] for p in parts])
    total = sum(p['seconds'] for p in parts)

    def add(key):
        values = [p[key] for p in parts]
        return None if any(v is None for v in values) else sum(values)

    return {
        'received': add('received'),
        'expected': add('expected'),
        'missed': add('missed'),
        'overruns': add('overruns'),
        'p50': float(np.percentile(jitter, 50)),
        'p99': float(np.percentile(jitter, 99)),
        'max': float(jitter.max()),
        'cpu': 100 * sum(p['cpu_s'] for p in parts) / total,
    }


def start(cmd: list[str]) -> subprocess.Popen:
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    for line in proc.stdout:
        if 'ready' in line:
            break
    threading.Thread(target=proc.stdout.read, daemon=True).start()
    return proc


def stop(proc: subprocess.Popen) -> None:
    os.kill(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--seconds', type=float, default=60.0)
    parser.add_argument('--rounds', type=int, default=4)
    args = parser.parse_args()
    rclpy.init()
    probe = Probe()
    parts: dict[str, list[dict]] = {'simulator': [], 'bare rclpy': []}
    segment = args.seconds / args.rounds
    for _ in range(args.rounds):
        sim = start(
            [
                sys.executable,
                '-m',
                'football_ros.cli',
                'simulator',
                '--ros-args',
                '-p',
                f'publish_rate:={args.rate}',
                '-p',
                'hold_rate:=0.0',
            ]
        )
        try:
            parts['simulator'].append(probe.measure(sim.pid, segment, args.rate, keep_flying=True))
        finally:
            stop(sim)
        time.sleep(1.0)
        bare = start([sys.executable, str(HERE / 'bare_publisher.py'), str(args.rate)])
        try:
            parts['bare rclpy'].append(
                probe.measure(bare.pid, segment, args.rate, keep_flying=False)
            )
        finally:
            stop(bare)
        time.sleep(1.0)
    probe.executor.shutdown(timeout_sec=2.0)
    probe.thread.join(timeout=2.0)
    probe.node.destroy_node()
    rclpy.try_shutdown()
    results = {name: pooled(p) for name, p in parts.items()}

    sim_r, bare_r = results['simulator'], results['bare rclpy']
    print(
        f'\nfootball_ros simulator vs bare rclpy publisher: {args.rate:g} Hz, '
        f'{args.seconds:g} s each '
        f'in {args.rounds} alternating rounds, subscriber in another process, '
        f'{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}\n'
    )
    print(f'{"metric":<28}{"simulator":>12}{"bare rclpy":>12}{"ratio":>8}')
    rows = [
        ('messages received', 'received', '{:.0f}'),
        ('messages expected', 'expected', '{:.0f}'),
        ('missed ticks (stamp gaps)', 'missed', '{}'),
        ("overruns (node's own count)", 'overruns', '{}'),
        ('jitter p50 [ms]', 'p50', '{:.3f}'),
        ('jitter p99 [ms]', 'p99', '{:.3f}'),
        ('jitter max [ms]', 'max', '{:.3f}'),
        ('CPU [% of one core]', 'cpu', '{:.1f}'),
    ]
    for label, key, fmt in rows:
        a, b = sim_r[key], bare_r[key]
        ratio = f'{a / b:.2f}' if isinstance(a, float) and isinstance(b, float) and b else '-'
        print(
            f'{label:<28}{fmt.format(a) if a is not None else "-":>12}'
            f'{fmt.format(b) if b is not None else "-":>12}{ratio:>8}'
        )
    print('\ntarget: 0 missed ticks; jitter p99 and max ratios <= 1 (no worse than bare rclpy)')


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('node (real-time publishing)', main))
