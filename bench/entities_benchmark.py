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
Many balls through simulation_interfaces: real-time pacing and lock-step speed (issue 19).

    .venv/bin/python bench/entities_benchmark.py [--seconds 4] [--repeats 5] [--priority 50]
        [--draws 3]

Real time: for each (balls, publish_rate) the simulator (a subprocess) spawns the balls with
SpawnEntities, throws them while paused with SetEntityState (lobs of 60 m/s at 80 deg: 12 s in
the air, each on football/<name>/pose and .../odom and one /tf per tick), plays, and its CPU time
(/proc/<pid>/stat) and late or skipped ticks (its /diagnostics) are measured over
``--seconds`` while every ball flies: first with nobody subscribed to the entity topics (the
simulator skips those), then with this client subscribed (raw) to every pose, odom and /tf.
Baselines from the same run and the same process: the idle simulator (no flight) at that
rate and the single-ball path (the default entity flown by a flight order, as the release
node does: today's six state topics, /tf, markers).
CPU per ball-second = (CPU - idle CPU) / (balls x seconds). Every case runs twice: the
simulator pacing on the normal scheduler (thread_priority 0, the default) and on SCHED_FIFO
(thread_priority ``--priority``; skipped where the machine refuses it). Before each, two
floors at that rate and scheduling for the same window: a bare Python pacing loop (the
simulator's, no ROS, no work), alone: the late ticks that scheduling alone costs; and the
publishing floor: that loop encoding (the simulator's encoders) and publishing the messages of
the subscribed window (every ball's pose and odom and one TFMessage per tick) to a client
subscribed to all of them as this one is, with no simulation and no executor: what publishing
alone costs. Late ticks vary from run to run: ``--draws`` runs every case that many times and
lists each run's late ticks.

Lock-step: paused, StepSimulation(steps=1000) of 1 ms steps (1 s of flight) for 1 and 100
balls in the air, timed end to end through the service (median of ``--repeats``); the same
through the SimulateSteps action; 200 calls of StepSimulation(steps=1) (medians of the first
and the last 50); baselines: the offline Flight.state_at of one ball for 1 s in this process,
a GetSimulationState and a StepSimulation(steps=0) round trip (the call without a step).
Each measurement runs in a fresh client process: an rclpy client process that has made many
calls gets its answers ever later (its executor creates more tasks per call, measured in
the rclpy client's profile) while the simulator's handler takes the same, and a new process
does not: the client's cost, not the simulator's. Targets: real time with 0 missed ticks;
lock-step >= 500x real time for 1 ball, >= 50x for 100.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
import statistics
import subprocess
import sys
import tempfile
import time

os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from football_ros.nodes import qos  # noqa: E402
from football_ros.physics import Flight, Release  # noqa: E402
from football_ros.physics.frames import BODY_FRAME, FIELD_FRAME  # noqa: E402
from football_ros.requests import FlightOrder  # noqa: E402
from geometry_msgs.msg import PoseStamped  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
import rclpy  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from simulation_interfaces.action import SimulateSteps  # noqa: E402
from simulation_interfaces.msg import (  # noqa: E402
    EntityState,
    Resource,
    Result,
    SimulationState,
    SpawnEntity as SpawnEntityMsg,
)
from simulation_interfaces.srv import (  # noqa: E402
    GetSimulationState,
    ResetSimulation,
    SetEntityState,
    SetSimulationState,
    SpawnEntities,
    StepSimulation,
)
from std_msgs.msg import String  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

NODE = '/football_simulator'
LOB = Release(speed=40.0, elevation_deg=75.0)
LOCK_STEP_LOB = Release(speed=60.0, elevation_deg=80.0)  # 12 s in the air


class Simulator:
    """The simulator node in a subprocess, its CPU time and its diagnostics."""

    def __init__(self, rate: float, log_dir: Path, priority: int = 0) -> None:
        self.log = log_dir / f'simulator_{rate:g}_{priority}.log'
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', 'simulator', '--ros-args', '-p',
             f'publish_rate:={rate}', '-p', 'max_entities:=200', '-p', 'marker_rate:=30.0',
             '-p', f'thread_priority:={priority}'],
            stdout=open(self.log, 'w'), stderr=subprocess.STDOUT, cwd=REPO,
            env=dict(os.environ, PYTHONPATH=str(REPO)),
        )
        deadline = time.monotonic() + 120.0
        while 'ready' not in self.log.read_text():
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f'simulator did not start:\n{self.log.read_text()}')
            time.sleep(0.1)

    def stop(self) -> None:
        self.proc.send_signal(2)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def cpu_ns(pid: int) -> int:
    """CPU time [ns] of every thread of process ``pid`` so far (schedstat: ns resolution)."""
    total = 0
    for task in Path(f'/proc/{pid}/task').iterdir():
        try:
            total += int((task / 'schedstat').read_text().split()[0])
        except (OSError, ValueError, IndexError):  # a thread that just ended
            pass
    return total


def cpu_seconds(pid: int) -> float:
    """CPU seconds (user + system) of process ``pid`` so far."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class Bench:
    """Service clients and a /diagnostics subscription in this process."""

    def __init__(self, server: str = NODE, share: Bench | None = None) -> None:
        """Clients of the node named ``server``; ``share``: another Bench's node and executor."""
        self.server = server
        self.clients = {}
        self.action = None  # the SimulateSteps client, made at the first goal
        self.status = {}
        if share is not None:  # the owner's node, executor, /diagnostics and flight orders
            self.node, self.executor, self.orders = share.node, share.executor, share.orders
            return
        rclpy.init()
        self.node = rclpy.create_node('entities_benchmark')
        # One executor, waited on with spin_once: rclpy's spin_until_future_complete leaves a
        # task per call in a long-lived executor, and every later call walks them (docs/envs.md).
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.node.create_subscription(
            DiagnosticArray, qos.DIAGNOSTICS, self._on_diag, qos.DIAGNOSTICS_QOS
        )
        self.orders = self.node.create_publisher(String, qos.FLIGHT_ORDER, qos.ORDER)

    def _on_diag(self, msg) -> None:
        for status in msg.status:
            if not status.name.endswith('event'):
                self.status = {kv.key: kv.value for kv in status.values}

    def client(self, srv_type, name: str):
        client = self.clients.get(name)
        if client is None:
            client = self.clients[name] = self.node.create_client(
                srv_type, f'{self.server}/{name}', qos_profile=qos.service_qos())
            if not client.wait_for_service(timeout_sec=30.0):
                raise SystemExit(f'no {name}')
        return client

    def call(self, srv_type, name: str, request, ok: bool = True, timeout: float = 120.0):
        """Call the simulator's service ``name``; the answer, or None after ``timeout`` [s]."""
        future = self.client(srv_type, name).call_async(request)
        if not self.spin_until(future.done, timeout):
            return None
        return self._checked(name, future.result(), ok)

    def call_many(self, srv_type, name: str, requests: list, ok: bool = True) -> list:
        """Send ``requests`` at once (the server keeps 1000 waiting); return the responses."""
        client = self.client(srv_type, name)
        futures = [client.call_async(request) for request in requests]
        if not self.spin_until(lambda: all(f.done() for f in futures), 120.0):
            raise SystemExit(f'{name}: not every call answered in 120 s')
        return [self._checked(name, f.result(), ok) for f in futures]

    @staticmethod
    def _checked(name: str, response, ok: bool):
        if ok and hasattr(response, 'result') and response.result.result != Result.RESULT_OK:
            raise SystemExit(f'{name}: {response.result.error_message}')
        return response

    def spin_until(self, condition, timeout: float) -> bool:
        """Spin until ``condition()`` holds or ``timeout`` [s] has passed; whether it holds."""
        end = time.monotonic() + timeout
        while not condition() and time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.05)
        return bool(condition())

    def spin(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.05)

    def count_all(self, balls: int, topic) -> tuple[list, list[int]]:
        """
        Subscribe (raw: this client only counts) to every ball's pose and odom and to a /tf.

        ``topic(k, leaf)`` names ball k's ``pose`` or ``odom`` topic, ``topic(None, 'tf')``
        the /tf. Returns the subscriptions and the one-element count of messages received.
        """
        received = [0]

        def count(_msg) -> None:
            received[0] += 1

        subs = [
            self.node.create_subscription(msg_type, topic(k, leaf), count, qos.STATE, raw=True)
            for k in range(balls)
            for msg_type, leaf in ((PoseStamped, 'pose'), (Odometry, 'odom'))
        ] + [self.node.create_subscription(TFMessage, topic(None, 'tf'), count, qos.TF_QOS,
                                           raw=True)]
        return subs, received

    def late_ticks(self) -> tuple[int, int]:
        """Return the simulator's late (caught up) and skipped (never published) ticks."""
        self.status = {}
        if not self.spin_until(lambda: 'overruns' in self.status, 60.0):
            raise SystemExit("no simulator's /diagnostics in 60 s")
        return int(self.status['overruns']), int(self.status['skipped_ticks'])

    def set_state(self, state: int) -> None:
        request = SetSimulationState.Request(state=SimulationState(state=state))
        self.call(SetSimulationState, 'set_simulation_state', request, ok=False)

    def reset(self, scope: int = ResetSimulation.Request.SCOPE_ALL) -> None:
        self.call(ResetSimulation, 'reset_simulation', ResetSimulation.Request(scope=scope))

    def spawn_and_throw(self, n: int, release: Release = LOB) -> None:
        spawns = [
            SpawnEntityMsg(name=f'b{k}', entity_resource=Resource(uri='football_ros://american'))
            for k in range(n)
        ]
        self.call(SpawnEntities, 'spawn_entities', SpawnEntities.Request(spawn_requests=spawns))
        self.throw(n, release)

    def throw(self, n: int, release: Release = LOB) -> None:
        """Throw balls b0 .. b<n-1> from their release, 0.5 m apart along y (SetEntityState)."""
        st = release.initial_state()
        requests = []
        for k in range(n):
            state = EntityState()
            p, o = state.pose.position, state.pose.orientation
            p.x, p.y, p.z = 0.0, 0.5 * k, 0.0
            o.x, o.y, o.z, o.w = st.attitude.tolist()
            v, w = state.twist.linear, state.twist.angular
            v.x, v.y, v.z = st.velocity.tolist()
            w.x, w.y, w.z = st.angular_velocity().tolist()
            requests.append(SetEntityState.Request(entity=f'b{k}', state=state))
        self.call_many(SetEntityState, 'set_entity_state', requests)

    def step(self, steps: int) -> float:
        start = time.perf_counter()
        self.call(StepSimulation, 'step_simulation', StepSimulation.Request(steps=steps))
        return time.perf_counter() - start

    def simulate_steps(self, steps: int) -> float:
        """
        Send one SimulateSteps goal and wait for its result; return the wall time [s].

        One action client for the benchmark's life, as a pipeline keeps one: a client made per
        goal makes the server discover its five endpoints every time, which costs the server
        more than the goal (and more with every entity's publishers to match against).
        """
        if self.action is None:
            self.action = ActionClient(self.node, SimulateSteps,
                                       f'{self.server}/simulate_steps')
            if not self.action.wait_for_server(timeout_sec=30.0):
                raise SystemExit('simulate_steps: no action server in 30 s')
        start = time.perf_counter()
        goal = self.action.send_goal_async(SimulateSteps.Goal(steps=steps))
        done = None
        if self.spin_until(goal.done, 60.0):
            done = goal.result().get_result_async()
        if done is None or not self.spin_until(done.done, 60.0):
            raise SystemExit('simulate_steps: no answer in 60 s')
        return time.perf_counter() - start


def window(bench: Bench, pid: int, seconds: float) -> tuple[float, int, int, float]:
    """CPU seconds, late and skipped ticks of the simulator, and this client's CPU seconds."""
    late, skipped = bench.late_ticks()
    cpu = cpu_seconds(pid)
    own = time.process_time()
    bench.spin(seconds)
    own = time.process_time() - own
    cpu = cpu_seconds(pid) - cpu
    late_after, skipped_after = bench.late_ticks()
    return cpu, late_after - late, skipped_after - skipped, own


def real_time(bench: Bench, pid: int, balls: int, seconds: float) -> dict:
    """Idle, one default ball and ``balls`` spawned balls at the simulator's rate."""
    out = {}
    bench.reset()
    bench.spin(0.5)
    out['idle'] = window(bench, pid, seconds)
    # The single-ball path: a flight order for the default entity (as the release node sends).
    bench.orders.publish(String(data=FlightOrder.from_release('bench', LOB).to_json()))
    bench.spin(0.5)
    out['single'] = window(bench, pid, seconds)
    bench.reset()
    # Thrown while paused (SpawnEntities, then SetEntityState each), all fly from PLAYING on:
    # 12 s lobs, in the air through both windows.
    bench.set_state(SimulationState.STATE_PAUSED)
    start = time.monotonic()
    bench.spawn_and_throw(balls, LOCK_STEP_LOB)
    throw_s = time.monotonic() - start
    bench.spin(1.0)  # the new publishers' discovery traffic settles
    bench.set_state(SimulationState.STATE_PLAYING)
    bench.spin(0.5)
    out['many'] = window(bench, pid, seconds)
    # The same with a subscriber on every entity topic and /tf.
    subs, received = bench.count_all(
        balls, lambda k, leaf: qos.TF if k is None else qos.entity_topic(f'b{k}', leaf))
    bench.spin(1.0)  # discovery
    received[0] = 0
    out['subscribed'] = window(bench, pid, seconds)
    out['received'] = received[0]
    for sub in subs:
        bench.node.destroy_subscription(sub)
    out['throw_s'] = throw_s
    bench.reset()
    return out


def lock_step(bench: Bench, pid: int, balls: int, repeats: int) -> dict:
    """
    Median wall time of 1 s of flight (1000 steps) with ``balls`` in the air, paused.

    The balls are thrown once (12 s lobs) and stepped on: StepSimulation(1000) ``repeats``
    times, SimulateSteps(1000) as often, then (one ball) 1000 x StepSimulation(1).
    """
    bench.set_state(SimulationState.STATE_PAUSED)
    bench.reset()
    bench.spawn_and_throw(balls, LOCK_STEP_LOB)
    bench.step(1)  # the client's discovery, outside the timings
    cpu = cpu_ns(pid)
    service = [bench.step(1000) for _ in range(repeats)]
    service_cpu = (cpu_ns(pid) - cpu) * 1e-9 / repeats
    cpu = cpu_ns(pid)
    action = [bench.simulate_steps(1000) for _ in range(repeats)]
    action_cpu = (cpu_ns(pid) - cpu) * 1e-9 / repeats
    singles = None
    if balls == 1:  # per call: the first and the last 50 of 200 (the client slows down)
        calls = [bench.step(1) for _ in range(200)]
        singles = (statistics.median(calls[:50]), statistics.median(calls[-50:]))
    bench.reset()
    bench.set_state(SimulationState.STATE_PLAYING)
    return {
        'service': statistics.median(service),
        'action': statistics.median(action),
        'service_cpu': service_cpu,
        'action_cpu': action_cpu,
        'singles': singles,
    }


def offline_second() -> float:
    times = []
    for _ in range(5):
        flight = Flight.from_release(LOB)
        start = time.perf_counter()
        flight.state_at(1.0)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def pace(rate: float, seconds: float, priority: int, work=None) -> dict:
    """
    Measure the floor of the machine: a bare pacing loop (the simulator's, no ROS, no work).

    Sleeps to absolute deadlines k / ``rate`` for ``seconds`` and counts late ticks as the
    simulator does (whole periods behind at each wake-up), on SCHED_FIFO at ``priority`` if
    > 0 (``refused`` says why not). ``work(t)``, if given, is each tick's work (t [s] since
    the start); ``cpu`` is this process's CPU seconds over the loop; ``late_at`` lists the
    late wake-ups as [time.monotonic() s, ticks behind] (CLOCK_MONOTONIC: comparable across
    processes).
    """
    from football_ros.nodes.simulator import fifo_priority

    refused = fifo_priority(priority) if priority else None
    period = int(round(1e9 / rate))
    cpu = time.process_time()
    next_due = start = time.monotonic_ns()
    end = start + int(seconds * 1e9)
    late = []
    while next_due < end:
        now = time.monotonic_ns()
        if now < next_due:
            time.sleep(min(next_due - now, 50_000_000) * 1e-9)
            continue
        if now - next_due >= period:
            late.append([now * 1e-9, (now - next_due) // period])
        while next_due <= now:
            if work is not None:
                work((next_due - start) * 1e-9)
            next_due += period
    return {'late': int(sum(n for _t, n in late)), 'late_at': late, 'refused': refused,
            'cpu': time.process_time() - cpu}


def publish_floor(rate: float, balls: int, seconds: float, priority: int) -> dict:
    """
    Measure the publishing floor: the simulator's messages, encoded and published, no simulation.

    Publishes ``balls`` poses, odometries and one TFMessage per tick on :func:`_floor_topic` (the
    simulator's own encoders, mb.EntityMessages, with moving states), paced by the bare loop of
    :func:`pace` on this main thread (no executor) at ``priority``, once every topic has a
    subscriber (:func:`floor_client`), for ``seconds``. Returns its CPU seconds and late ticks.
    """
    from football_ros.nodes import messages as mb

    rclpy.init()
    node = rclpy.create_node('publish_floor')
    try:
        pubs = [(node.create_publisher(PoseStamped, _floor_topic(k, 'pose'), qos.STATE),
                 node.create_publisher(Odometry, _floor_topic(k, 'odom'), qos.STATE),
                 mb.EntityMessages(FIELD_FRAME, f'{BODY_FRAME}/b{k}')) for k in range(balls)]
        tf_pub = node.create_publisher(TFMessage, _floor_topic(None, 'tf'), qos.TF_QOS)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline and not (
                tf_pub.get_subscription_count() and all(
                    a.get_subscription_count() and b.get_subscription_count()
                    for a, b, _ in pubs)):
            time.sleep(0.05)
        time.sleep(1.0)  # discovery settles

        def tick(t: float) -> None:
            stamp = mb.time_msg(time.time_ns())
            transforms = []
            for k, (pose_pub, odom_pub, msgs) in enumerate(pubs):
                position = [10.0 * t, 0.5 * k, 20.0 * t - 4.9 * t * t]
                orientation = [0.0, -0.2, 0.0, 0.98]
                pose_pub.publish(msgs.pose(stamp, position, orientation))
                odom_pub.publish(msgs.odom(stamp, position, orientation,
                                           [10.0, 0.0, 20.0 - 9.8 * t], [60.0, 0.1, 0.2]))
                transforms.append((msgs, stamp, position, orientation))
            tf_pub.publish(mb.tf_message_bytes(transforms))

        return pace(rate, seconds, priority, tick)
    finally:
        node.destroy_node()
        rclpy.shutdown()


def floor_client(balls: int, seconds: float) -> dict:
    """Subscribe (raw) to every topic of :func:`publish_floor` for ``seconds``: the count."""
    bench = Bench()
    _subs, received = bench.count_all(balls, _floor_topic)
    try:
        bench.spin(seconds)
        return {'received': received[0]}
    finally:
        bench.node.destroy_node()
        rclpy.shutdown()


def _floor_topic(k: int | None, leaf: str) -> str:
    """Topic of :func:`publish_floor`: ball k's pose or odom, or (k None) its /tf."""
    return f'floor/{leaf}' if k is None else f'floor/b{k}/{leaf}'


def floor(rate: float, balls: int, seconds: float, priority: int) -> dict:
    """Run :func:`publish_floor` and :func:`floor_client` side by side (two processes)."""
    argv = [sys.executable, __file__, '--phase', 'publish_floor', '--no-record', '--rate',
            str(rate), '--balls', str(balls), '--seconds', str(seconds), '--priority',
            str(priority)]
    publisher = subprocess.Popen(argv, stdout=subprocess.PIPE, text=True)
    try:
        client = run_phase('floor_client', balls=balls, seconds=seconds + 4.0)
        out, _ = publisher.communicate(timeout=120)
    finally:
        if publisher.poll() is None:
            publisher.kill()
    result = json.loads(out.strip().splitlines()[-1])
    result['received'] = client['received']
    return result


def phase(args) -> dict:
    """
    Run one measurement in this (fresh) client process and return its numbers.

    A fresh process each: an rclpy client process that has seen many of the simulator's
    endpoints come and go gets its answers ever later (client side: a new process is fast).
    """
    if args.phase == 'pace':
        return pace(args.rate, args.seconds, args.priority)
    if args.phase == 'publish_floor':
        return publish_floor(args.rate, args.balls, args.seconds, args.priority)
    if args.phase == 'floor_client':
        return floor_client(args.balls, args.seconds)
    bench = Bench()
    try:
        if args.phase == 'realtime':
            return real_time(bench, args.pid, args.balls, args.seconds)
        if args.phase == 'lockstep':
            return lock_step(bench, args.pid, args.balls, args.repeats)
        request = GetSimulationState.Request()
        bench.call(GetSimulationState, 'get_simulation_state', request)  # discovery
        bench.set_state(SimulationState.STATE_PAUSED)
        bench.step(0)
        times, steps0 = [], []
        for _ in range(20):
            start = time.perf_counter()
            bench.call(GetSimulationState, 'get_simulation_state', request)
            times.append(time.perf_counter() - start)
            steps0.append(bench.step(0))
        bench.set_state(SimulationState.STATE_PLAYING)
        return {'round_trip': statistics.median(times), 'step0': statistics.median(steps0)}
    finally:
        bench.node.destroy_node()
        rclpy.shutdown()


def run_phase(name: str, **options) -> dict:
    argv = [sys.executable, __file__, '--phase', name, '--no-record']  # the parent records
    for key, value in options.items():
        argv += [f'--{key}', str(value)]
    out = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    if out.returncode != 0:
        raise SystemExit(f'phase {name} failed:\n{out.stdout}\n{out.stderr[-3000:]}')
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seconds', type=float, default=4.0, help='real-time window [s] (<= 5)')
    parser.add_argument('--repeats', type=int, default=5, help='lock-step repeats (median)')
    parser.add_argument('--draws', type=int, default=3,
                        help='real-time runs of every case (late ticks vary from run to run)')
    parser.add_argument('--priority', type=int, default=50,
                        help='thread_priority of the real-time rows (SCHED_FIFO; 0: none)')
    parser.add_argument('--phase', help=argparse.SUPPRESS, choices=(
        'realtime', 'lockstep', 'round_trip', 'pace', 'publish_floor', 'floor_client'))
    parser.add_argument('--rate', type=float, help=argparse.SUPPRESS)
    parser.add_argument('--pid', type=int, help=argparse.SUPPRESS)
    parser.add_argument('--balls', type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.phase:
        print(json.dumps(phase(args)))
        return 0
    seconds = min(args.seconds, 5.0)
    rows = []
    priorities = (0, args.priority) if args.priority > 0 else (0,)
    refused = None
    cases = [(balls, rate, priority) for balls, rate in ((100, 100.0), (10, 1000.0))
             for priority in priorities]
    draws: dict[tuple, list] = {}  # (balls, rate, priority) -> per draw: late ticks by row
    with tempfile.TemporaryDirectory() as tmp:
        for draw, (balls, rate, priority) in (
                (d, case) for d in range(max(args.draws, 1)) for case in cases):
            bare = run_phase('pace', rate=rate, seconds=seconds, priority=priority)
            if bare['refused']:
                refused = bare['refused']
                continue
            published = floor(rate, balls, seconds, priority)
            sim = Simulator(rate, Path(tmp), priority)
            try:
                r = run_phase('realtime', pid=sim.proc.pid, balls=balls, seconds=seconds)
                draws.setdefault((balls, rate, priority), []).append(
                    [bare['late'], published['late']]
                    + [r[k][1] for k in ('idle', 'single', 'many', 'subscribed')])
                if draw == 0:
                    rows.append((balls, rate, priority, bare['late'], published, r))
                if draw == 0 and rate == 100.0 and priority == 0:
                    trips = run_phase('round_trip')
                    steps = {
                        n: run_phase('lockstep', pid=sim.proc.pid, balls=n, repeats=args.repeats)
                        for n in (1, 100)
                    }
            finally:
                sim.stop()
    offline = offline_second()

    print(f'Real time ({seconds:g} s windows; CPU = simulator process user + system; late = '
          'published after its deadline, skipped = never published; pacing = the simulator '
          'thread_priority: normal scheduler or SCHED_FIFO)')
    print('| case | pacing | rate Hz | balls | CPU s/s | CPU ms per tick (budget: the period) '
          '| late ticks | skipped ticks | CPU ms per ball-second | vs single-ball path '
          '| client CPU s/s (of 2 cores, with the simulator) |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for balls, rate, priority, floor_late, published, r in rows:
        pacing = f'FIFO {priority}' if priority else 'normal'
        print(f'| bare pacing loop (floor: no ROS, no work, {seconds:g} s alone) | {pacing} '
              f'| {rate:g} | 0 | | | {floor_late} | | | | |')
        cpu = published['cpu']
        print('| publishing floor (the messages of the subscribed window, encoded and published '
              f'by that loop, no simulation, no executor; delivered: {published["received"]}) '
              f'| {pacing} | {rate:g} | {balls} | {cpu / seconds:.3f} '
              f'| {1e3 * cpu / (seconds * rate):.3f} (of {1e3 / rate:g}) | {published["late"]} '
              '| | | | |')
        idle_cpu = r['idle'][0]
        single = (r['single'][0] - idle_cpu) / seconds
        for name, n, (cpu, late, skipped, client) in (
            ('idle (baseline)', 0, r['idle']),
            ('single-ball path (baseline)', 1, r['single']),
            ('spawned balls (no subscriber on their topics)', balls, r['many']),
            ('spawned balls, every pose/odom and /tf subscribed', balls, r['subscribed']),
        ):
            per = (cpu - idle_cpu) / (max(n, 1) * seconds)
            ratio = '' if n == 0 else f'{per / single:.3f}'
            per_text = '' if n == 0 else f'{1e3 * per:.2f}'
            print(f'| {name} | {pacing} | {rate:g} | {n} | {cpu / seconds:.3f} '
                  f'| {1e3 * cpu / (seconds * rate):.3f} (of {1e3 / rate:g}) | {late} | {skipped} '
                  f'| {per_text} | {ratio} | {client / seconds:.3f} '
                  f'({(cpu + client) / seconds:.2f}) |')
        print(f'| (throwing the {balls} balls through the services: {r["throw_s"]:.2f} s; '
              f'messages the subscribed window delivered: {r["received"]}) | | | | | | | | | | |')
    if refused:
        print(f'(SCHED_FIFO {args.priority} refused on this machine: {refused}; only the normal '
              'scheduler was measured)')
    print(f'\nLate ticks of each of {max(args.draws, 1)} runs (the table above is the first; '
          f'{seconds:g} s windows, {seconds:g} x rate ticks each)')
    names = ('bare pacing loop', 'publishing floor', 'idle', 'single-ball path',
             'spawned, unsubscribed', 'spawned, subscribed')
    print('| pacing | rate Hz | balls | ' + ' | '.join(names) + ' |')
    print('|---' * (3 + len(names)) + '|')
    for (balls, rate, priority), per in draws.items():
        pacing = f'FIFO {priority}' if priority else 'normal'
        print(f'| {pacing} | {rate:g} | {balls} | ' + ' | '.join(
            ', '.join(str(run[i]) for run in per) for i in range(len(names))) + ' |')
    print()
    print('Lock-step: 1 s of flight (1000 steps of 1 ms), paused, end to end (median)')
    print('(simulator CPU = the CPU time of its threads per call, /proc schedstat: the work, '
          'without the waits for a core)')
    print('| case | wall ms | x real time | simulator CPU ms per call | x real time on its CPU |')
    print('|---|---|---|---|---|')
    print(f'| offline Flight.state_at, 1 ball, in process (baseline) | {1e3 * offline:.2f} '
          f'| {1.0 / offline:.0f} | | |')
    print(f'| GetSimulationState round trip (baseline) | {1e3 * trips["round_trip"]:.2f} '
          '| | | |')
    print(f'| StepSimulation(0) round trip (baseline: the call, no step) '
          f'| {1e3 * trips["step0"]:.2f} | | | |')
    for n, r in steps.items():
        for name, wall, cpu in (
            ('StepSimulation(1000)', r['service'], r['service_cpu']),
            ('SimulateSteps(1000)', r['action'], r['action_cpu']),
        ):
            print(f'| {name}, {n} ball(s) | {1e3 * wall:.2f} | {1.0 / wall:.0f} '
                  f'| {1e3 * cpu:.2f} | {1.0 / cpu:.0f} |')
        if r['singles'] is not None:
            first, last = r['singles']
            print(f'| StepSimulation(1), {n} ball, per call: first 50 of 200 calls '
                  f'| {1e3 * first:.2f} | {1e-3 / first:.2f} | | |')
            print(f'| StepSimulation(1), {n} ball, per call: last 50 of 200 calls (same client) '
                  f'| {1e3 * last:.2f} | {1e-3 / last:.2f} | | |')
    return 0


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('entities (simulation_interfaces)', main))
