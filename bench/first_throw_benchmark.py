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
The first throw after start-up (issue 12.1): from "ready" to the answer, and where DDS waits.

    .venv/bin/python bench/first_throw_benchmark.py [--trials 10] [--domains 162-165]
        [--modes fastdds,package] [--demo 0] [--baseline 10]

Each trial runs on its own ROS domain (cycling through ``--domains``; nothing else of ours runs
there), with ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, once per mode, the modes interleaved
so that they share the machine's load:

- ``fastdds``: ``FASTRTPS_DEFAULT_PROFILES_FILE`` names a profile of the user's that writes out
  the Fast DDS default announcement period (3 s): what every process did before the package
  shipped its profile, and a test that a user's own profile is respected;
- ``package``: the variable unset, so every process uses what the package chooses
  (football_ros/nodes/fastdds_profile.xml).

A throw trial starts ``football-ros simulator`` and ``football-ros release`` (the README's
set-up), notes the time each logs "ready" (the ROS log stamp), then runs ``football-ros throw
--verbose`` (the default spiral pass) as a new process and reads the stamps it logs: process
start -> participant up ("looking") -> matched the release node -> answer received. The
baseline trial is a bare rclpy pair of fresh processes (a server with one publisher and one
subscription, then a client that waits until it has matched both): the same discovery with
nothing of ours in it (plain rclpy never picks the package's profile, so in both columns it runs
with the 3 s period: a control of the machine's state in each mode's turn). ``--demo N`` also
times N runs of ``football-ros demo`` per mode (its nodes' last "ready" -> the release node's
answer, and how many requests it sent).

The table gives p50, max and the count over 1 s (the issue's target: the answer within 1 s of
the nodes reporting ready) per mode, and the package/fastdds ratio of p50 and max. Every process
started here is ended here, by its PID (SIGINT, then SIGKILL after 10 s).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import time

from football_ros.nodes.dds import PROFILE_VARIABLES

CLI = [sys.executable, '-m', 'football_ros.cli']
LOG_LINE = re.compile(r'\[(?:DEBUG|INFO|WARN|ERROR|FATAL)\] \[(\d+\.\d+)\] \[([^\]]+)\]: (.*)')
MODES = ('fastdds', 'package')
FASTDDS_DEFAULTS = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="fastdds_defaults" is_default_profile="true">
      <rtps><builtin><discovery_config>
        <leaseAnnouncement><sec>3</sec><nanosec>0</nanosec></leaseAnnouncement>
      </discovery_config></builtin></rtps>
    </participant>
  </profiles>
</dds>
"""
"""A user's own profile holding the Fast DDS 2.14 default announcement period (3 s)."""
TARGET_S = 1.0

BARE_SERVER = """
import sys, time
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('bench_bare_server')
pub = node.create_publisher(String, 'bench/bare/response', 10)
node.create_subscription(String, 'bench/bare/request', pub.publish, 10)
print('ready', flush=True)
try:
    rclpy.spin(node)
except (KeyboardInterrupt, Exception):  # SIGINT: rclpy shuts the context down
    pass
"""
BARE_CLIENT = """
import time
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node('bench_bare_client')
up = time.time()
sub = node.create_subscription(String, 'bench/bare/response', lambda m: None, 10)
pub = node.create_publisher(String, 'bench/bare/request', 10)
deadline = time.monotonic() + 20.0
while (pub.get_subscription_count() == 0 or sub.get_publisher_count() == 0) and (
        time.monotonic() < deadline):
    rclpy.spin_once(node, timeout_sec=0.005)
print(up, time.time() if pub.get_subscription_count() and sub.get_publisher_count() else -1)
"""


def parse_domains(text: str) -> list[int]:
    """'162-165' or '162,164' -> the domain ids."""
    out = []
    for part in text.split(','):
        lo, _, hi = part.partition('-')
        out.extend(range(int(lo), int(hi or lo) + 1))
    return out


def environment(domain: int, mode: str, work: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in PROFILE_VARIABLES}
    if mode == 'fastdds':
        env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(work / 'fastdds_defaults.xml')
    env.update(ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    return env


def stamps(text: str) -> list[tuple[float, str, str]]:
    """(wall time [s], logger, message) of every ROS log line in ``text``."""
    return [(float(m[1]), m[2], m[3]) for m in LOG_LINE.finditer(text)]


def first_stamp(text: str, needle: str) -> float | None:
    return next((t for t, _, msg in stamps(text) if msg.startswith(needle)), None)


class Started:
    """A child process started here, ended here by its PID."""

    def __init__(self, args: list[str], env: dict, log: Path | None = None, **kw) -> None:
        self.log = log
        out = open(log, 'w') if log else subprocess.PIPE
        self.proc = subprocess.Popen(
            args, env=env, stdout=out, stderr=subprocess.STDOUT if log else None, text=True, **kw
        )
        if log:
            out.close()

    def text(self) -> str:
        return self.log.read_text() if self.log else ''

    def end(self) -> None:
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.kill(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


def wait_ready(nodes: list[Started], timeout: float = 120.0) -> list[float]:
    """Poll the nodes' logs until each has logged 'ready'; their log stamps."""
    end = time.monotonic() + timeout
    while True:
        ready = [first_stamp(n.text(), 'ready') for n in nodes]
        if all(r is not None for r in ready):
            return ready
        for n in nodes:
            if n.proc.poll() is not None:
                raise RuntimeError(f'{n.log.name} exited early:\n{n.text()[-2000:]}')
        if time.monotonic() > end:
            raise RuntimeError('the nodes did not get ready')
        time.sleep(0.005)


def throw_trial(domain: int, mode: str, work: Path, index: int) -> dict:
    env = environment(domain, mode, work)
    folder = work / f'{mode}_{index}'
    folder.mkdir()
    nodes = [
        Started([*CLI, 'simulator'], env, folder / 'simulator.log'),
        Started([*CLI, 'release'], env, folder / 'release.log'),
    ]
    try:
        ready = wait_ready(nodes)
        spawn = time.time()
        proc = subprocess.run(
            [*CLI, 'throw', '--verbose', '--id', f'bench-{index}'],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        for node in nodes:
            node.end()
    (folder / 'throw.log').write_text(proc.stdout + proc.stderr)
    looking = first_stamp(proc.stderr, 'looking')
    matched = first_stamp(proc.stderr, 'matched')
    answer = first_stamp(proc.stderr, 'answer')
    if proc.returncode != 0 or None in (looking, matched, answer):
        raise RuntimeError(f'throw failed ({proc.returncode}); see {folder}')
    return {
        'throw: process start -> participant up': looking - spawn,
        'throw: process start -> matched': matched - spawn,
        'throw: participant up -> matched': matched - looking,
        'throw: matched -> answer': answer - matched,
        'last node ready -> answer': answer - max(ready),
    }


def bare_trial(domain: int, mode: str, work: Path) -> dict:
    env = environment(domain, mode, work)
    server = Started([sys.executable, '-c', BARE_SERVER], env)
    try:
        while server.proc.stdout.readline().strip() != 'ready':
            if server.proc.poll() is not None:
                raise RuntimeError('the bare server exited early')
        spawn = time.time()
        client = [sys.executable, '-c', BARE_CLIENT]
        out = subprocess.run(
            client, env=env, capture_output=True, text=True, timeout=60
        ).stdout.split()[-2:]
    finally:
        server.end()
    up, matched = float(out[0]), float(out[1])
    if matched < 0:
        raise RuntimeError('the bare client never matched the bare server')
    return {
        'bare rclpy: process start -> matched': matched - spawn,
        'bare rclpy: participant up -> matched': matched - up,
    }


def demo_trial(domain: int, mode: str, work: Path, index: int) -> dict:
    env = environment(domain, mode, work)
    folder = work / f'demo_{mode}_{index}'
    demo = Started([*CLI, 'demo', '--out', str(folder)], env, work / f'demo_{mode}_{index}.log')
    try:
        answered = None
        end = time.monotonic() + 120
        while answered is None and time.monotonic() < end and demo.proc.poll() is None:
            if '[demo] release node:' in demo.text():
                answered = time.time()  # polled every 5 ms: within 5 ms of the line
            time.sleep(0.005)
        demo.proc.wait(timeout=120)
    finally:
        demo.end()
    if answered is None:
        raise RuntimeError(f'the demo got no answer; see {demo.log}')
    ready = [first_stamp((folder / f'{n}.log').read_text(), 'ready')
             for n in ('simulator', 'release', 'recorder')]
    return {
        'demo: last node ready -> answer': answered - max(ready),
        'demo: requests sent': float(demo.text().count('[demo] throwing:')),
    }


def summarize(results: dict[str, list[dict]], modes: list[str]) -> None:
    metrics = list(dict.fromkeys(k for rows in results.values() for row in rows for k in row))
    head = f'{"":42s}' + ''.join(f'{m + " p50":>13s}{"max":>8s}{">1 s":>6s}' for m in modes)
    ratio = len(modes) == 2
    print(head + ('   ratio p50   max' if ratio else ''))
    for metric in metrics:
        line = f'{metric:42s}'
        p50, top = [], []
        for mode in modes:
            values = [row[metric] for row in results[mode] if metric in row]
            if not values:
                line += f'{"-":>13s}{"-":>8s}{"-":>6s}'
                p50.append(None)
                top.append(None)
                continue
            p50.append(statistics.median(values))
            top.append(max(values))
            over = sum(v > TARGET_S for v in values) if 'requests' not in metric else 0
            line += f'{p50[-1]:13.3f}{top[-1]:8.3f}{over:3d}/{len(values):<2d}'
        if ratio and None not in p50 and p50[0] > 0 and top[0] > 0:
            line += f'{p50[1] / p50[0]:12.2f}{top[1] / top[0]:6.2f}'
        print(line)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--trials', type=int, default=10, help='throw trials per mode')
    parser.add_argument('--baseline', type=int, default=10, help='bare rclpy trials per mode')
    parser.add_argument('--demo', type=int, default=0, help='demo runs per mode')
    parser.add_argument('--domains', default='162-165', help='ROS domains to cycle through')
    parser.add_argument('--modes', default='fastdds,package', help=f'of: {", ".join(MODES)}')
    parser.add_argument('--keep', help='folder for the logs (default: a temporary one)')
    args = parser.parse_args(argv)
    domains = parse_domains(args.domains)
    modes = args.modes.split(',')
    if not set(modes) <= set(MODES):
        parser.error(f'--modes: choose from {", ".join(MODES)}')
    results: dict[str, list[dict]] = {m: [] for m in modes}
    work = Path(args.keep or tempfile.mkdtemp(prefix='first_throw_'))
    work.mkdir(parents=True, exist_ok=True)
    (work / 'fastdds_defaults.xml').write_text(FASTDDS_DEFAULTS)
    turn = 0
    started = time.monotonic()
    for kind, count in (('bare', args.baseline), ('throw', args.trials), ('demo', args.demo)):
        for i in range(count):
            for mode in modes:
                domain = domains[turn % len(domains)]
                turn += 1
                if kind == 'bare':
                    row = bare_trial(domain, mode, work)
                elif kind == 'throw':
                    row = throw_trial(domain, mode, work, i)
                else:
                    row = demo_trial(domain, mode, work, i)
                results[mode].append(row)
                shown = ' '.join(f'{v:.3f}' for v in row.values())
                print(f'# {kind} {i} {mode:8s} domain {domain}: {shown}', flush=True)
    load = os.getloadavg()[0]
    print(f'\n{sum(len(r) for r in results.values())} trials in '
          f'{time.monotonic() - started:.0f} s, load average {load:.2f}, logs in {work}')
    summarize(results, modes)
    return 0


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('first throw', main))
