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
Worst-case decision time of a release request; bursts and floods of requests to the nodes.

Every request up to the byte limit is decided in bounded time: times the release node's two
steps without ROS (reading the text, judging the release) for a typical request and for hostile
ones of up to ``max_request_bytes``, each case's ratio to the typical request.

Every request reaches the node and gets one answer: the release node (with a simulator) and the
planner in subprocesses (own ROS domain, loopback), a client here sends a burst (``--burst``
requests at once) and a flood (``--rate`` per second for ``--seconds``; ``--keep-all-seconds``
for the KEEP_ALL client, whose publish waits for the node), with and without a CPU
hog (two busy-loop processes), the client's writer with the documented request QoS (KEEP_LAST
1000) and with the package's own clients' KEEP_ALL (``qos.REQUEST_WRITER``). Counted: sent,
read by the node (its own counter), lost on the way as
DDS reports it to the node's reader, answered (once each), busy; the client's own reader is
10000 deep and counts what DDS reports lost to it. Where requests go missing is the column
where the count first falls short of ``sent``.

    .venv/bin/python bench/request_benchmark.py [--repeat N] [--burst N] [--rate R] \
        [--seconds S] [--keep-all-seconds S] [--nodes release planner] [--no-flood]
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import re
import signal
import statistics
import subprocess
import sys
import threading
import time

from football_ros.requests import (
    FlightOrder,
    MAX_REQUEST_BYTES,
    read_request,
    release_from_request,
    RequestError,
)

LIMIT = MAX_REQUEST_BYTES


def _fill(prefix: str, unit: str, suffix: str) -> str:
    """``prefix + unit * n + suffix`` as long as fits in LIMIT bytes."""
    n = (LIMIT - len(prefix) - len(suffix)) // len(unit)
    return prefix + unit * n + suffix


CASES = {
    'typical request': json.dumps(
        {'id': 'pass-1', 'speed': 25.0, 'spin_rpm': 650, 'beta0_deg': -2}
    ),
    'full-model request': json.dumps(
        {
            'id': 'wind',
            'model': 'full',
            'aero': {'wind': [0, -4, 0]},
            'ball_params': {'mass': 0.42},
            'position': [1, 2, 1.8],
        }
    ),
    'deep nesting [[[...': '[' * (LIMIT // 2) + ']' * (LIMIT // 2),
    'deep nesting {a: {a: ...': _fill('', '{a: ', ''),
    'deep block nesting': ''.join(' ' * (2 * i) + 'a:\n' for i in range(2000))[:LIMIT],
    'flat mapping, many keys': '{'
    + ', '.join(f'k{i}: 1' for i in range(20000))[: LIMIT - 2]
    + '}',
    'long list': _fill('{id: l, position: [', '1, ', '1]}'),
    'long string value': _fill('{id: s, ball: "', 'x', '"}'),
    'many digits': _fill('{id: d, speed: ', '9', '}'),
    'many exponents': _fill('[', '1e999, ', '1]'),
    'aliases everywhere': _fill('a: &x 1\n', 'b: *x\n', ''),
    'duplicate keys': _fill('{', 'speed: 1, ', 'speed: 2}'),
    'tags everywhere': _fill('[', '!!float 1, ', '1]'),
    'malformed at the end': '[' + ', '.join('1' for _ in range(40000))[: LIMIT - 4] + ', [}',
}


def decide(text: str) -> str:
    """Decide as the release node does, up to the flight order (no prediction, no ROS)."""
    try:
        request_id, keys = read_request(text)
        release = release_from_request(request_id, keys)
        order = FlightOrder.from_release(request_id, release, 'bench-1')
        FlightOrder.from_json(order.to_json()).flight(0.001)
        return 'accepted'
    except RequestError as exc:
        return f'rejected: {str(exc)[:50]}'


def decision_times(args) -> None:
    decide(CASES['typical request'])  # compile/load the kernels once
    rows = []
    for name, text in CASES.items():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            outcome = decide(text)
            times.append(time.perf_counter() - t0)
        rows.append((name, len(text.encode()), statistics.median(times), max(times), outcome))
    base = rows[0][2]
    print(f'{"case":26} {"bytes":>6} {"median ms":>10} {"max ms":>8} {"x typical":>10}  outcome')
    for name, size, med, worst, outcome in rows:
        print(
            f'{name:26} {size:6d} {med * 1e3:10.3f} {worst * 1e3:8.3f} '
            f'{med / base:10.1f}  {outcome}'
        )
    print(f'worst case: {max(r[3] for r in rows) * 1e3:.1f} ms (limit {LIMIT} bytes)')


COUNTS = re.compile(
    r'\[(release|planner)\] (\d+) requests received: .*?(\d+) busy(?:; (\d+) lost)?'
)


class Hog:
    """Two busy-loop processes (the CPU hog), ended by their PIDs."""

    def __init__(self, on: bool) -> None:
        loop = [sys.executable, '-c', 'while True: pass']
        self.procs = [subprocess.Popen(loop) for _ in range(2)] if on else []

    def stop(self) -> None:
        for proc in self.procs:
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait()


class Started:
    """A node program in a subprocess, its output in a file, stopped by its PID."""

    def __init__(self, command: str, log: Path, code: Path | None = None) -> None:
        self.log = log
        self._out = open(log, 'w')
        env = dict(os.environ, PYTHONPATH=str(code)) if code else None
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', command], stdout=self._out,
            stderr=subprocess.STDOUT, cwd=code, env=env,
        )
        deadline = time.monotonic() + 300.0
        while 'ready' not in log.read_text():
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f'{command} did not start:\n{log.read_text()[-2000:]}')
            time.sleep(0.1)

    def stop(self) -> str:
        os.kill(self.proc.pid, signal.SIGINT)
        try:
            self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.kill(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self._out.close()
        return self.log.read_text()


def _request(node: str, rid: str, k: int) -> str:
    if node == 'planner':
        return json.dumps({'id': rid, 'target': [20 + k % 10, 1, 1], 'hit_n': 0})
    return json.dumps({'id': rid, 'speed': 15 + k % 20, 'spin_rpm': 300 + k % 500})


def flood_run(
    node: str, pattern: str, hog_on: bool, keep_all: bool, args, tmp: Path,
    code: Path | None = None,
) -> list:
    """
    One row: start the node(s) (of the checkout ``code``), send, wait for the answers, count.

    ``args``: burst, rate, seconds. Columns as the table of :func:`floods` prints them.
    """
    import rclpy
    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.executors import SingleThreadedExecutor
    from diagnostic_msgs.msg import DiagnosticStatus
    from std_msgs.msg import String

    from football_ros.nodes import qos
    from football_ros.nodes.dds import use_package_profile

    use_package_profile()
    tag = f'{node}-{pattern}-{int(hog_on)}-{int(keep_all)}'
    sim = Started('simulator', tmp / f'{tag}-sim.log', code) if node == 'release' else None
    target = Started(node, tmp / f'{tag}.log', code)
    context = rclpy.Context()
    rclpy.init(context=context)
    client = rclpy.create_node(f'bench_client_{os.getpid()}', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(client)
    answers: dict[str, int] = {}
    busy, client_lost = [0], [0]

    def on_answer(msg) -> None:
        answers[msg.name] = answers.get(msg.name, 0) + 1
        busy[0] += 'busy' in msg.message[:6]

    def on_lost(info) -> None:
        client_lost[0] += info.total_count_change

    response, request = (
        (qos.RELEASE_RESPONSE, qos.RELEASE_REQUEST) if node == 'release'
        else (qos.PLAN_RESPONSE, qos.PLAN_REQUEST)
    )
    client.create_subscription(
        DiagnosticStatus, response, on_answer, qos.inbox(qos.REQUEST),
        event_callbacks=SubscriptionEventCallbacks(message_lost=on_lost),
    )
    pub = client.create_publisher(String, request, qos.REQUEST_WRITER if keep_all else qos.REQUEST)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set() and context.ok():
            executor.spin_once(timeout_sec=0.05)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    hog = Hog(hog_on)
    try:
        deadline = time.monotonic() + 60.0
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)  # the node's side of the discovery too
        seconds = args.keep_all_seconds if keep_all else args.seconds
        count = args.burst if pattern == 'burst' else int(args.rate * seconds)
        sent, failed = [], 0
        start = time.monotonic()
        for k in range(count):
            rid = f'{tag}-{k}'
            try:
                pub.publish(String(data=_request(node, rid, k)))
                sent.append(rid)
            except Exception:  # noqa: BLE001 - a KEEP_ALL writer that stayed full
                failed += 1
            if pattern == 'flood':
                time.sleep(max(0.0, start + (k + 1) / args.rate - time.monotonic()))
        quiet_since, seen = time.monotonic(), 0
        while len(answers) < len(sent) and time.monotonic() - quiet_since < 20.0:
            time.sleep(0.2)
            if len(answers) != seen:
                quiet_since, seen = time.monotonic(), len(answers)
    finally:
        hog.stop()
        log = target.stop()
        if sim is not None:
            sim.stop()
        stop.set()
        spinner.join(timeout=5.0)
        context.try_shutdown()
    match = COUNTS.search(log)
    received, lost = (int(match.group(2)), int(match.group(4) or -1)) if match else (-1, -1)
    once = sum(1 for rid in sent if answers.get(rid) == 1)
    return [node, pattern, 'yes' if hog_on else 'no', 'KEEP_ALL' if keep_all else
            'KEEP_LAST 1000', len(sent) + failed, failed, received, lost, once,
            len(sent) - len(answers), busy[0], client_lost[0]]


def floods(args) -> None:
    tmp = Path(os.environ.get('TMPDIR', '/tmp')) / f'football_requests_{os.getpid()}'
    tmp.mkdir(parents=True, exist_ok=True)
    rows = []
    for node in args.nodes:
        for hog_on in (False, True):
            for pattern, keep_all in (('burst', False), ('flood', False), ('flood', True)):
                rows.append(flood_run(node, pattern, hog_on, keep_all, args, tmp))
    print(f'\nburst: {args.burst} at once; flood: {args.rate:g}/s for {args.seconds:g} s '
          f'(KEEP_ALL client: {args.keep_all_seconds:g} s); '
          f'ROS_DOMAIN_ID={os.environ["ROS_DOMAIN_ID"]}; logs in {tmp}\n')
    print('| node | pattern | CPU hog | client writer | sent | publish failed | read by the '
          'node | lost (DDS, node) | answered once | unanswered | busy | lost (DDS, client) |')
    print('|---|---|---|---|' + '---:|' * 8)
    for row in rows:
        print('| ' + ' | '.join(str(c) for c in row) + ' |')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--repeat', type=int, default=20)
    parser.add_argument('--burst', type=int, default=1000)
    parser.add_argument('--rate', type=float, default=1000.0)
    parser.add_argument('--seconds', type=float, default=10.0)
    parser.add_argument('--keep-all-seconds', type=float, default=2.0,
                        help='flood length of the KEEP_ALL client (its publish waits)')
    parser.add_argument('--no-flood', action='store_true', help='the decision times only')
    parser.add_argument('--nodes', nargs='+', choices=('release', 'planner'),
                        default=['release', 'planner'])
    args = parser.parse_args()
    decision_times(args)
    if not args.no_flood:
        floods(args)


if __name__ == '__main__':
    os.environ.setdefault('ROS_DOMAIN_ID', str(170 + os.getpid() % 30))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('requests', main))
