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
Issues 22 and 31: a stranger's campaign against the nodes, in two set-ups of the same run.

    .venv/bin/python bench/security_campaign.py [--hammer-seconds 5] [--throws 5] \
        [--before /work/main] [--no-record]

``open``: simulator, release node and planner started with ``allow_reconfigure:=true`` (every
guarded parameter writable, as before issue 22); ``default``: as installed (guards on). This
checkout's nodes in subprocesses; a stranger in this process (own ROS domain, loopback discovery
only), with entities_benchmark's Bench for the simulation_interfaces calls. Measured:

- issue 22: forged OK acknowledgements with no simulator running; forged ERROR acknowledgements
  naming another node and the simulator; the parameters of the issue (frame_id=map,
  publish_rate=1, max_request_bytes=64, a 1 MB child_frame_id: accepted or refused, the
  simulator's RSS before and after); an answer forged before the release node's; pause and
  reset 100 times a second (the simulator's log lines and bytes per second);
- issue 31: GetEntities and GetEntitiesStates with backtracking name filters over 20 entities
  with 63-character names (the slowest of 3 answers and its result per filter; the /tf messages
  received meanwhile against publish_rate x the time, with the default ball in flight); bursts
  of concurrent calls from 4 clients with deep answer queues, paused (1000 each of
  GetSimulationState, StepSimulation(1), GetEntityState, SetSimulationState(pause), the pause
  service; 200 SimulateSteps goals; 300 cancel_goal of one long goal): answered / sent; the
  planner's ``execute: true`` without an id (does the release node answer under the
  ``release_request_id`` the planner reports?); ``use_sim_time`` set to true on each node
  (accepted or refused; put back if accepted); a forged /clock at 42 s while use_sim_time is
  false (do the football/pose stamps follow it?);
- request topics: a burst (1000 at once) and a flood (1000/s for ``--hammer-seconds``) of
  requests to the release node and to the planner (bench/request_benchmark.py's runs, nodes
  restarted for each): answered exactly once / sent.

Every wait is bounded and ends on its condition; every node started is stopped by its PID.
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
REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # this checkout's package, not the installed one

from builtin_interfaces.msg import Time  # noqa: E402
from diagnostic_msgs.msg import DiagnosticStatus  # noqa: E402
from entities_benchmark import Bench, LOCK_STEP_LOB, NODE  # noqa: E402
from football_ros.nodes import qos  # noqa: E402
from football_ros.requests import FlightOrder  # noqa: E402
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rcl_interfaces.srv import GetParameters, SetParameters  # noqa: E402
import rclpy  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.parameter import Parameter, parameter_value_to_python  # noqa: E402
from request_benchmark import flood_run  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from simulation_interfaces.action import SimulateSteps  # noqa: E402
from simulation_interfaces.msg import (  # noqa: E402
    Resource,
    Result,
    SimulationState,
    SpawnEntity as SpawnEntityMsg,
)
from simulation_interfaces.srv import (  # noqa: E402
    GetEntities,
    GetEntitiesStates,
    GetEntityState,
    GetSimulationState,
    SetSimulationState,
    SpawnEntities,
    StepSimulation,
)
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402

OK, ERROR = b'\x00', b'\x02'  # DiagnosticStatus levels (a byte)
HOSTILE_FILTERS = {  # issue 31: each froze a simulator that matched with Python's re
    "'.*' * 30 + 'X'": '.*' * 30 + 'X',
    "'.*' * 10 + 'X'": '.*' * 10 + 'X',
    '(a+)+$': '(a+)+$',
    '(a|aa)+$': '(a|aa)+$',
}
LONG_NAMES = ['a' * 60 + f'_{k:02d}' for k in range(20)]  # 63 characters each
CALLS_PER_FILTER = 3
CLIENTS, BURST, GOALS, CANCELS = 4, 1000, 200, 300
FORGED_CLOCK_S = 42  # a /clock of 1970
RESULT_NAMES = {v: k[len('RESULT_'):] for k, v in vars(Result).items()
                if k.startswith('RESULT_') and isinstance(v, int)}


def rss_mb(pid: int) -> float:
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1]) / 1024.0
    return float('nan')


class Node:
    """A football_ros node in a subprocess, its output in a file; stopped by its PID."""

    started: list[Node] = []  # every one started: main stops them all, whatever happened

    def __init__(self, command: str, *args: str, log: Path, code: Path = REPO) -> None:
        self.log_path = log
        self._log = open(log, 'w')
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', command, *args],
            stdout=self._log, stderr=subprocess.STDOUT, cwd=code,
            env=dict(os.environ, PYTHONPATH=str(code)),
        )
        Node.started.append(self)
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
        self.plans: list[DiagnosticStatus] = []
        self.node.create_subscription(
            DiagnosticStatus, qos.PLAN_RESPONSE, self.plans.append, qos.REQUEST
        )
        self.plan_requests = self.node.create_publisher(String, qos.PLAN_REQUEST, qos.REQUEST)
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

    def get_param(self, node: str, name: str):
        result = self.call(GetParameters, f'/{node}/get_parameters',
                           GetParameters.Request(names=[name]))
        return parameter_value_to_python(result.values[0]) if result else None

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


def fly_default_ball(bench: Bench) -> None:
    """Throw the default ball (a 12 s lob, by flight order): /tf and its pose at publish_rate."""
    bench.spin_until(lambda: bench.orders.get_subscription_count() > 0, 20.0)
    order = FlightOrder.from_release('campaign', LOCK_STEP_LOB)
    bench.orders.publish(String(data=order.to_json()))
    bench.spin(0.5)


def answer_text(answer) -> str:
    if answer is None:
        return 'no answer'
    result = answer.result
    if result.result == Result.RESULT_OK:
        return f'OK ({len(answer.entities if hasattr(answer, "entities") else [])} matched)'
    return f'{RESULT_NAMES.get(result.result, result.result)}: {result.error_message[:60]}'


def hostile_filters(bench: Bench, stranger: Stranger, rows: dict[str, str]) -> None:
    """Call the name filters of HOSTILE_FILTERS over 63-character names; count /tf meanwhile."""
    spawns = [SpawnEntityMsg(name=name, entity_resource=Resource(uri='football_ros://american'))
              for name in LONG_NAMES]
    bench.call(SpawnEntities, 'spawn_entities', SpawnEntities.Request(spawn_requests=spawns))
    rate = stranger.get_param('football_simulator', 'publish_rate')
    fly_default_ball(bench)
    subs, received = bench.count_all(0, lambda _k, _leaf: qos.TF)
    bench.spin_until(lambda: received[0] > 0, 10.0)
    received[0], start = 0, time.monotonic()
    services = ((GetEntities, 'get_entities'), (GetEntitiesStates, 'get_entities_states'))
    for srv_type, name in services:  # the clients' discovery, outside the timings
        bench.call(srv_type, name, srv_type.Request())
    for label, pattern in HOSTILE_FILTERS.items():
        cells = []
        for srv_type, name in services:
            request = srv_type.Request()
            request.filters.filter = pattern
            slowest, answer = 0.0, None
            for _ in range(CALLS_PER_FILTER):
                t0 = time.perf_counter()
                answer = bench.call(srv_type, name, request, ok=False, timeout=60.0)
                slowest = max(slowest, time.perf_counter() - t0)
                if answer is None:
                    break
            cells.append(f'{1e3 * slowest:.1f} ms, {answer_text(answer)}')
        rows[f'filter {label} (GetEntities; GetEntitiesStates): slowest answer, result'] = (
            '; '.join(cells))
    bench.spin(max(0.0, start + 1.0 - time.monotonic()))  # a window of 1 s at least
    elapsed = time.monotonic() - start
    rows['/tf during the filter calls: received / expected at publish_rate'] = (
        f'{received[0]} / {rate * elapsed:.0f}' if rate else f'{received[0]} / ?')
    for sub in subs:
        bench.node.destroy_subscription(sub)


def burst(bench: Bench, srv_type, name: str, request, count: int = BURST) -> int:
    """``count`` calls at once from CLIENTS clients (deep answer queues): how many answered."""
    clients = [bench.node.create_client(srv_type, name, qos_profile=qos.service_qos())
               for _ in range(CLIENTS)]
    try:
        if not all(c.wait_for_service(timeout_sec=20.0) for c in clients):
            return 0
        futures = [clients[k % CLIENTS].call_async(request) for k in range(count)]
        bench.spin_until(lambda: all(f.done() for f in futures), 120.0)
        return sum(f.done() for f in futures)
    finally:
        for client in clients:
            bench.node.destroy_client(client)


def bursts(bench: Bench, rows: dict[str, str]) -> None:
    """Bursts of calls to the simulator's services and its action, paused: answered / sent."""
    bench.set_state(SimulationState.STATE_PAUSED)
    paused = SetSimulationState.Request(state=SimulationState(state=SimulationState.STATE_PAUSED))
    for label, srv_type, name, request in (
        ('GetSimulationState', GetSimulationState, 'get_simulation_state',
         GetSimulationState.Request()),
        ('StepSimulation(steps=1)', StepSimulation, 'step_simulation',
         StepSimulation.Request(steps=1)),
        ('GetEntityState', GetEntityState, 'get_entity_state',
         GetEntityState.Request(entity=LONG_NAMES[0])),
        ('SetSimulationState (pause)', SetSimulationState, 'set_simulation_state', paused),
        ('pause service (SetBool)', SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=True)),
    ):
        full = name if '/' in name else f'{NODE}/{name}'
        rows[f'burst of {BURST} from {CLIENTS} clients, {label}: answered / sent'] = (
            f'{burst(bench, srv_type, full, request)} / {BURST}')
    deep = qos.service_qos()
    clients = [ActionClient(bench.node, SimulateSteps, f'{NODE}/simulate_steps',
                            goal_service_qos_profile=deep, result_service_qos_profile=deep,
                            cancel_service_qos_profile=deep) for _ in range(CLIENTS)]
    try:
        ready = all(c.wait_for_server(timeout_sec=20.0) for c in clients)
        goals = [clients[k % CLIENTS].send_goal_async(SimulateSteps.Goal(steps=100))
                 for k in range(GOALS if ready else 0)]
        bench.spin_until(lambda: all(f.done() for f in goals), 120.0)
        rows[f'burst of {GOALS} SimulateSteps goals from {CLIENTS} clients: answered / sent'] = (
            f'{sum(f.done() for f in goals)} / {GOALS}')
        outcomes = [f.result().get_result_async() for f in goals
                    if f.done() and f.result().accepted]
        bench.spin_until(lambda: all(f.done() for f in outcomes), 60.0)  # one goal at a time
        long_goal = clients[0].send_goal_async(SimulateSteps.Goal(steps=600_000))
        bench.spin_until(long_goal.done, 20.0)
        handle = long_goal.result() if long_goal.done() else None
        cancels = ([handle.cancel_goal_async() for _ in range(CANCELS)]
                   if handle is not None and handle.accepted else [])
        bench.spin_until(lambda: all(f.done() for f in cancels), 120.0)
        rows[f'burst of {CANCELS} cancel_goal for one goal: answered / sent'] = (
            f'{sum(f.done() for f in cancels)} / {CANCELS}' if cancels
            else 'the goal was not accepted')
        if cancels:
            ended = handle.get_result_async()
            bench.spin_until(ended.done, 120.0)
    finally:
        for client in clients:
            client.destroy()
    bench.set_state(SimulationState.STATE_PLAYING)


def sim_time(bench: Bench, stranger: Stranger, rows: dict[str, str]) -> None:
    """use_sim_time set by a stranger on each node; a forged /clock while it is false."""
    for node in ('football_simulator', 'football_release', 'football_planner'):
        accepted = stranger.set_param(node, 'use_sim_time', True)
        rows[f'set use_sim_time=true on {node}'] = 'accepted' if accepted else 'refused'
        if accepted:  # back to the wall clock for what follows
            stranger.set_param(node, 'use_sim_time', False)
    stamps: list[int] = []
    clock = bench.node.create_publisher(Clock, qos.CLOCK, qos.CLOCK_QOS)
    sub = bench.node.create_subscription(
        PoseStamped, qos.POSE, lambda msg: stamps.append(msg.header.stamp.sec), qos.STATE)
    fly_default_ball(bench)
    stamps.clear()
    forged = Clock(clock=Time(sec=FORGED_CLOCK_S))
    end = time.monotonic() + 5.0
    while len(stamps) < 100 and time.monotonic() < end:
        clock.publish(forged)
        bench.executor.spin_once(timeout_sec=0.01)
    followed = sum(1 for sec in stamps if abs(sec - FORGED_CLOCK_S) < 3600)
    rows['forged /clock (use_sim_time false): football/pose stamps follow it'] = (
        f'{"yes" if followed else "no"} ({followed} of {len(stamps)} poses)')
    bench.node.destroy_subscription(sub)
    bench.node.destroy_publisher(clock)


def planner_execute(stranger: Stranger, rows: dict[str, str]) -> None:
    """Check that a planner's execute: true without an id throws under the id it reports."""
    key = 'planner execute:true without an id: release answered under the reported id'
    deadline = time.monotonic() + 20.0
    while (stranger.plan_requests.get_subscription_count() == 0
           or stranger.node.count_subscribers('/' + qos.RELEASE_REQUEST) < 1
           or stranger.node.count_publishers('/' + qos.RELEASE_REQUEST) < 2) \
            and time.monotonic() < deadline:  # the release node reads, the planner (and we) write
        time.sleep(0.05)
    time.sleep(1.0)  # the planner's own view of the release node
    stranger.plans.clear()
    stranger.plan_requests.publish(String(data=json.dumps(
        {'target': [20.0, 1.0, 0.0], 'hit_n': 0, 'execute': True})))
    deadline = time.monotonic() + 60.0
    while not stranger.plans and time.monotonic() < deadline:
        time.sleep(0.05)
    if not stranger.plans:
        rows[key] = 'no (no plan answer)'
        return
    values = {kv.key: kv.value for kv in stranger.plans[0].values}
    release_id = values.get('release_request_id')
    if release_id is None:
        rows[key] = f'no (not thrown: {stranger.plans[0].message[-60:]})'
        return
    deadline = time.monotonic() + 20.0
    while time.monotonic() < deadline and not any(
            r.name == release_id for r in list(stranger.responses)):
        time.sleep(0.05)
    answered = [r.name for r in list(stranger.responses) if r.name == release_id]
    rows[key] = 'yes' if answered else f"no (no release answer under '{release_id}')"


def campaign(setup: str, args, tmp: Path, stranger: Stranger, bench: Bench) -> dict[str, str]:
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
    # Issue 31: hostile name filters, bursts of calls, the planner's execute, use_sim_time.
    planner = Node('planner', *extra, log=tmp / f'{setup}-planner.log', code=code)
    hostile_filters(bench, stranger, rows)
    bursts(bench, rows)
    planner_execute(stranger, rows)
    sim_time(bench, stranger, rows)
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
    planner.stop()
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
    bench = Bench()  # simulation_interfaces calls (rclpy's default context)
    try:
        setups = (('before',) if args.before else ()) + ('open', 'default')
        results = {setup: campaign(setup, args, tmp, stranger, bench) for setup in setups}
    finally:
        for node in Node.started:
            node.stop()
        stranger.close()
        bench.node.destroy_node()
        rclpy.try_shutdown()
    print(f'ROS_DOMAIN_ID={os.environ["ROS_DOMAIN_ID"]}, logs in {tmp}\n')
    titles = {'before': f'before ({args.before})', 'open': 'open (allow_reconfigure:=true)',
              'default': 'default (guards on)'}
    print('| attack | ' + ' | '.join(titles[s] for s in results) + ' |')
    print('|---|' + '---|' * len(results))
    for key in results['open']:
        print(f'| {key} | ' + ' | '.join(results[s].get(key, '-') for s in results) + ' |')
    return 0


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('security campaign', main))
