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
Issue 22's stranger campaign against the nodes, in two set-ups of the same run.

    .venv/bin/python bench/security_campaign.py [--hammer-seconds 5] [--throws 5] \
        [--before /work/main]

``open``: simulator and release node started with ``allow_reconfigure:=true`` (every guarded
parameter writable, as before issue 22); ``default``: as installed (guards on). A stranger node
in this process (own ROS domain, loopback discovery only) then: sets the parameters of the
issue (frame_id=map, publish_rate=1, max_request_bytes=64, a 1 MB frame_id); forges OK
acknowledgements with no simulator running; forges ERROR acknowledgements naming another node
and naming the simulator; answers requests before the release node; calls pause and reset
100 times a second and counts the simulator's log lines per second (its own stdout+stderr);
sends a burst (1000 at once) and a flood (1000/s for ``--hammer-seconds``) of requests to the
release node and to the planner (bench/request_benchmark.py's runs, nodes restarted for each).
Reported: how many attempts succeeded, the simulator's RSS before and after the big string,
log lines and bytes per second under the hammer, requests answered exactly once of those sent.
Everything is bounded in time and counts.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import threading
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(200 + os.getpid() % 30))
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('RCUTILS_LOGGING_BUFFERED_STREAM', '0')

from diagnostic_msgs.msg import DiagnosticStatus  # noqa: E402
from football_ros.nodes import qos  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402
import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from request_benchmark import flood_run  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
OK, ERROR = b'\x00', b'\x02'  # DiagnosticStatus levels (a byte)


def rss_mb(pid: int) -> float:
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1]) / 1024.0
    return float('nan')


class Node:
    """A football_ros node in a subprocess, its output in a file; stopped by its PID."""

    def __init__(self, command: str, *args: str, log: Path, code: Path = REPO) -> None:
        self.log_path = log
        self._log = open(log, 'w')
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', command, *args],
            stdout=self._log, stderr=subprocess.STDOUT, cwd=code,
            env=dict(os.environ, PYTHONPATH=str(code)),
        )
        deadline = time.monotonic() + 180.0
        while 'ready' not in log.read_text():
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f'{command} did not start:\n{log.read_text()[-2000:]}')
            time.sleep(0.1)

    def lines_and_bytes(self) -> tuple[int, int]:
        text = self.log_path.read_bytes()
        return text.count(b'\n'), len(text)

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.kill(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self._log.close()


class Stranger:
    """The hostile participant: one rclpy node spun in a thread."""

    def __init__(self) -> None:
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('stranger', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.responses: list[DiagnosticStatus] = []
        self.node.create_subscription(
            DiagnosticStatus, qos.RELEASE_RESPONSE, self.responses.append, qos.REQUEST
        )
        self.requests = self.node.create_publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
        self.answers = self.node.create_publisher(DiagnosticStatus, qos.RELEASE_RESPONSE,
                                                  qos.REQUEST)
        self.acks = self.node.create_publisher(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
        self.forge: tuple[bytes, str] | None = None  # (level, hardware_id) of forged acks
        self.node.create_subscription(String, qos.FLIGHT_ORDER, self._on_order, qos.ORDER)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.05)
            except Exception:
                if not self.context.ok():
                    return
                raise

    def _on_order(self, msg: String) -> None:
        if self.forge is not None:
            level, hardware_id = self.forge
            self.acks.publish(DiagnosticStatus(
                level=level, name=json.loads(msg.data)['order'], message='forged',
                hardware_id=hardware_id))

    def call(self, srv, name, request, timeout=5.0):
        client = self.node.create_client(srv, name)
        try:
            if not client.wait_for_service(timeout_sec=timeout):
                return None
            future = client.call_async(request)
            deadline = time.monotonic() + timeout
            while not future.done() and time.monotonic() < deadline:
                time.sleep(0.002)
            return future.result() if future.done() else None
        finally:
            self.node.destroy_client(client)

    def set_param(self, node: str, name: str, value) -> bool:
        request = SetParameters.Request(parameters=[Parameter(name, value=value)
                                                    .to_parameter_msg()])
        result = self.call(SetParameters, f'/{node}/set_parameters', request)
        return bool(result and result.results[0].successful)

    def throw(self, request_id: str, timeout: float = 5.0) -> DiagnosticStatus | None:
        """Send one default release; return the first answer under its id (or None)."""
        deadline = time.monotonic() + timeout
        while self.requests.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        self.requests.publish(String(data=f'{{id: {request_id}}}'))
        while time.monotonic() < deadline:
            for r in list(self.responses):
                if r.name == request_id:
                    return r
            time.sleep(0.01)
        return None

    def close(self) -> None:
        self.context.try_shutdown()  # the spinning thread returns first
        self._thread.join(timeout=2.0)
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()


def level(status) -> bytes:
    return bytes(status.level)[:1] if isinstance(status.level, bytes) else bytes([status.level])


def campaign(setup: str, args, tmp: Path, stranger: Stranger) -> dict[str, str]:
    extra = ['--ros-args', '-p', 'allow_reconfigure:=true'] if setup == 'open' else []
    code = Path(args.before) if setup == 'before' else REPO
    rows: dict[str, str] = {}
    # 1. forged OK acknowledgements, no simulator running.
    release = Node('release', *extra, log=tmp / f'{setup}-release.log', code=code)
    stranger.forge = (OK, '/football_simulator')
    accepted = sum(
        1 for k in range(args.throws)
        if (r := stranger.throw(f'{setup}-ok-{k}')) is not None and level(r) == OK
    )
    rows['forged OK accepted, no simulator'] = f'{accepted} / {args.throws}'
    simulator = Node('simulator', *extra, log=tmp / f'{setup}-simulator.log', code=code)
    time.sleep(1.0)
    # 2. forged ERROR acknowledgements naming another node, then naming the simulator.
    for label, hardware_id in (('another node', '/football_rival'),
                               ('the simulator', '/football_simulator')):
        stranger.forge = (ERROR, hardware_id)
        refused = sum(
            1 for k in range(args.throws)
            if (r := stranger.throw(f'{setup}-err-{label[:3]}-{k}')) is not None
            and level(r) == ERROR
        )
        rows[f'throws refused by a forged ERROR naming {label}'] = f'{refused} / {args.throws}'
    stranger.forge = None
    # 3. parameters of the attacks.
    for node, name, value in (('football_simulator', 'frame_id', 'map'),
                              ('football_simulator', 'publish_rate', 1.0),
                              ('football_release', 'max_request_bytes', 64)):
        rows[f'set {name}={value}'] = 'accepted' if stranger.set_param(node, name, value) \
            else 'refused'
    before = rss_mb(simulator.proc.pid)
    big = stranger.set_param('football_simulator', 'child_frame_id', 'x' * (1 << 20))
    time.sleep(2.0)
    rows['set a 1 MB child_frame_id'] = 'accepted' if big else 'refused'
    rows['simulator RSS before / after it [MB]'] = (
        f'{before:.0f} / {rss_mb(simulator.proc.pid):.0f}'
    )
    # 4. answering before the release node: a stranger's answer under the client's id.
    stranger.responses.clear()
    stranger.answers.publish(DiagnosticStatus(level=OK, name='race-1', message='accepted: forged'))
    first = stranger.throw('race-1')
    rows['a forged answer seen first by a client'] = (
        'yes' if first is not None and first.message == 'accepted: forged' else 'no'
    )
    # 5. pause and reset at 100 Hz: the simulator's log lines per second.
    lines0, bytes0 = simulator.lines_and_bytes()
    t0 = time.monotonic()
    calls = 0
    pause = stranger.node.create_client(SetBool, qos.PAUSE_SERVICE)
    reset = stranger.node.create_client(Trigger, qos.RESET_SERVICE)
    pause.wait_for_service(timeout_sec=5.0)
    reset.wait_for_service(timeout_sec=5.0)
    while time.monotonic() - t0 < args.hammer_seconds:
        pause.call_async(SetBool.Request(data=calls % 4 == 0))
        reset.call_async(Trigger.Request())
        calls += 2
        time.sleep(0.02)  # 50 cycles = 100 calls a second
    elapsed = time.monotonic() - t0
    time.sleep(1.0)
    lines1, bytes1 = simulator.lines_and_bytes()
    rows['calls per second (pause + reset)'] = f'{calls / elapsed:.0f}'
    rows['simulator log lines per second'] = f'{(lines1 - lines0) / elapsed:.0f}'
    rows['simulator log bytes per second'] = f'{(bytes1 - bytes0) / elapsed:.0f}'
    stranger.node.destroy_client(pause)
    stranger.node.destroy_client(reset)
    simulator.stop()
    release.stop()
    # 6. bursts and floods of requests: each answered once?
    flood = argparse.Namespace(burst=1000, rate=1000.0, seconds=args.hammer_seconds)
    for node in ('release', 'planner'):
        for pattern in ('burst', 'flood'):
            row = flood_run(node, pattern, False, False, flood, tmp / setup, code)
            what = 'burst of 1000' if pattern == 'burst' else f'flood 1000/s x {flood.seconds:g} s'
            rows[f'{node} requests, {what}: answered once / sent'] = f'{row[8]} / {row[4]}'
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[1])
    parser.add_argument('--hammer-seconds', type=float, default=5.0)
    parser.add_argument('--throws', type=int, default=5)
    parser.add_argument(
        '--before', metavar='CHECKOUT', help='also run the nodes of another checkout '
        '(e.g. /work/main before issue 22) as the baseline column',
    )
    args = parser.parse_args()
    args.throws = max(1, min(args.throws, 50))
    args.hammer_seconds = max(1.0, min(args.hammer_seconds, 60.0))
    tmp = Path(os.environ.get('TMPDIR', '/tmp')) / f'football_campaign_{os.getpid()}'
    for setup in ('before', 'open', 'default'):
        (tmp / setup).mkdir(parents=True, exist_ok=True)
    stranger = Stranger()
    try:
        setups = (('before',) if args.before else ()) + ('open', 'default')
        results = {setup: campaign(setup, args, tmp, stranger) for setup in setups}
    finally:
        stranger.close()
    print(f'ROS_DOMAIN_ID={os.environ["ROS_DOMAIN_ID"]}, logs in {tmp}\n')
    titles = {'before': f'before ({args.before})', 'open': 'open (allow_reconfigure:=true)',
              'default': 'default (guards on)'}
    print('| attack | ' + ' | '.join(titles[s] for s in results) + ' |')
    print('|---|' + '---|' * len(results))
    for key in results['open']:
        print(f'| {key} | ' + ' | '.join(results[s][key] for s in results) + ' |')
    return 0


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('security campaign', main))
