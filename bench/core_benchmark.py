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
The simulator against its own core: how much of its CPU is the physics.

    .venv/bin/python bench/core_benchmark.py [--draws 3] [--hogs 2] [--balls 1 100]
        [--rt-balls 999] [--seconds 4] [--soak 600] [--thread-priority 0]

Every figure is a ratio to a baseline measured in the same run, ``--draws`` times, with
``--hogs`` busy-loop processes beside it (a loaded machine):

- Lock-step: the simulator's CPU (its process, /proc, less its idle CPU paused) per
  StepSimulation (1000 steps) and per SimulateSteps goal (1000 steps) with N balls in the air
  (and its idle CPU: playing with nothing in the air, paused with a ball in it), over the bare
  core's CPU for the same steps in the client's thread (``Simulation.step_n(1000)``, in the
  same rounds as the simulator's calls, so that both meet the same load). Two floors: a
  do-nothing rclpy server offering StepSimulation and SimulateSteps (it answers at once),
  running beside the simulator and called in the same rounds, in turn with it ("less floor":
  (simulator - floor) / core); and the simulator's own call of one step (its executor with
  all its services, publishers and action; "less its 1 step": what the 999 further steps cost
  it, over the core's 1000). The default ball's
  lock-step (flown by a flight order) beside a spawned ball's. The simulator and the floor on
  each executor (``executor_type``: events, the default, and single_threaded, the baseline).
- Real time at 100 Hz: the simulator's CPU (cores) with ``--rt-balls`` balls in the air and a
  /tf subscriber (and the /tf messages received per tick published), with nobody subscribed (and
  the physics' share: the core's kernel pass for those balls in this process over the
  simulator's CPU per tick), and with 100 balls and every per-ball topic subscribed, beside
  its publishing floor (entities_benchmark.floor: the same messages encoded and published by a
  bare pacing loop to a client subscribed to all, no simulation, no executor).
- Soak (``--soak`` s): 100 balls re-thrown every 10 s at 100 Hz with a /tf subscriber: the
  simulator's RSS growth and late ticks beside two pacing loops run at the same time in other
  processes (no ROS, one thread): the bare loop (no work) and one busy for the simulator's CPU
  per tick of the same workload (its real-time row): on the normal scheduler a loaded machine
  delays a loop by the work it does a tick, so the second is the floor of the first target.
  The late ticks are also counted per minute of the soak for all three (:func:`windows`), so
  that a moment of load beside the run counts against all three in the same window; beside
  them the host's steal time per minute (:func:`steal_phase`): on a virtual machine the
  hypervisor takes a vCPU away now and then (FIFO loops pinned one to each vCPU were late
  exactly when /proc/stat showed their own vCPU stolen), and a loop that happens to sit on
  the other vCPU then is not late.

``--thread-priority`` > 0 puts the simulator's pacing thread (its ``thread_priority``) and the
bare pacing loop on SCHED_FIFO at that priority (root or an rtprio limit); its run is recorded
in its own section.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
from pathlib import Path
import statistics
import subprocess
import sys
import tempfile
import time

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'bench'))
sys.path.insert(0, str(REPO))

import entities_benchmark as eb  # noqa: E402
from football_ros.nodes import qos  # noqa: E402
from football_ros.nodes.runner import EXECUTOR_TYPES  # noqa: E402
from football_ros.physics import Flight  # noqa: E402
from football_ros.requests import FlightOrder  # noqa: E402
from football_ros.simulation import core  # noqa: E402
from football_ros.simulation.world import DEFAULT_ENTITY, FlightRun  # noqa: E402
from results import recorded  # noqa: E402
from simulation_interfaces.msg import SimulationState  # noqa: E402
from simulation_interfaces.srv import ResetSimulation  # noqa: E402
from std_msgs.msg import String  # noqa: E402

STEPS = 1000
REPEATS = 7
ROUNDS = 15  # batches of REPEATS calls, each from a fresh throw
ALL_BALLS = 100  # balls of the every-topic-subscribed row and of its publishing floor
SOAK_BALLS = 100
FLOOR_NODE = '/football_floor'  # the do-nothing server, beside the simulator (eb.NODE)
EXECUTORS = EXECUTOR_TYPES  # the simulator's executor_type: its default first


class BareCore:
    """The core alone (no ROS) with ``balls`` lobs in the air, stepped as the services step it."""

    def __init__(self, balls: int, default: bool = False) -> None:
        self.sim = core.Simulation(max_entities=balls + 1)
        self.names = [DEFAULT_ENTITY] if default else [
            self.sim.spawn(f'b{k}', 'football_ros://american', [0, 0.5 * k, 0], [0, 0, 0, 1]).name
            for k in range(balls)]
        self.sim.set_state(core.PAUSED)

    def throw(self) -> None:
        """Throw every ball afresh (a fresh throw before each round, as the simulator's)."""
        for name in self.names:
            self.sim.throw(name, FlightRun(name, Flight.from_release(eb.LOCK_STEP_LOB)))

    def step(self) -> None:
        self.sim.step_n(STEPS, 0)


def bare_tick(balls: int, seconds: float = 2.0) -> float:
    """CPU seconds of the core's kernel pass of one 100 Hz tick for ``balls`` lobs (no ROS)."""
    bare = BareCore(balls)
    bare.throw()
    sim = bare.sim
    sim.set_state(core.PLAYING)
    sim.tick(0, 10_000_000, 1.0, 1.0)
    n, spent, start = 0, 0.0, time.monotonic()
    while time.monotonic() - start < seconds:
        sim.tick(0, 10_000_000, 1.0, 1.0)  # takes the pass computed ahead
        before = time.thread_time()
        sim.integrate_ahead()  # the next tick's pass: the physics
        spent += time.thread_time() - before
        n += 1
    return spent / n


def idle_rate(pid: int, seconds: float = 2.0) -> float:
    """CPU seconds per second of process ``pid`` while nothing is asked of it."""
    cpu = eb.cpu_ns(pid)
    time.sleep(seconds)
    return (eb.cpu_ns(pid) - cpu) * 1e-9 / seconds


def per_call(measures: dict, rounds: int = ROUNDS) -> dict:
    """
    CPU seconds per call of each measure, less the idle CPU of what it measures.

    ``measures``: {key: (cpu_ns, idle, prepare, call)}, ``cpu_ns()`` the CPU nanoseconds so far
    of what is measured (a process, or this thread for the bare core), ``idle`` its CPU seconds
    per second at rest. In each of ``rounds`` rounds, the measures in turn (so that they share
    the load's drift): ``prepare()`` (a fresh throw), one ``call()`` outside the figure, then
    REPEATS calls measured; the figure is the median over the rounds (a round that met a burst
    of other work on the machine does not move it).
    """
    per_round = {key: [] for key in measures}
    for _ in range(rounds):
        for key, (cpu_ns, idle, prepare, call) in measures.items():
            prepare()
            call()
            cpu, wall = cpu_ns(), time.monotonic()
            for _ in range(REPEATS):
                call()
            used = (cpu_ns() - cpu) * 1e-9 - idle * (time.monotonic() - wall)
            per_round[key].append(used / REPEATS)
    return {key: statistics.median(values) for key, values in per_round.items()}


def lock_step_phase(pid: int, balls: list[int], floor_pid: int) -> dict:
    """
    Measure the simulator's CPU per call beside the floor server's and the bare core's.

    The floor server's calls ('floor ...') and the bare core's steps in this thread ('core
    ...') are interleaved with the simulator's in the same rounds, so that every ratio
    compares figures measured under the same load.
    """
    bench = eb.Bench()
    floor = eb.Bench(FLOOR_NODE, share=bench)
    out = {'idle playing': idle_rate(pid)}  # fresh: playing, nothing in the air
    bench.set_state(SimulationState.STATE_PAUSED)
    bench.spawn_and_throw(1, eb.LOCK_STEP_LOB)
    idle, floor_idle = idle_rate(pid), idle_rate(floor_pid)  # paused, a ball in the air
    out['idle paused'] = idle
    sim_cpu = functools.partial(eb.cpu_ns, pid)
    floor_cpu = functools.partial(eb.cpu_ns, floor_pid)

    def nothing() -> None:
        pass

    for n in balls:
        bench.set_state(SimulationState.STATE_PAUSED)
        bench.reset()
        bench.spawn_and_throw(n, eb.LOCK_STEP_LOB)
        # Each batch (REPEATS + 1 calls, at most 8 s of flight) from a fresh throw: the lobs
        # fly 12 s, so no ball lands inside one. The same calls of one step: the simulator's
        # own floor (its executor, services, publishers and action).
        throw = functools.partial(bench.throw, n, eb.LOCK_STEP_LOB)
        bare = BareCore(n)
        out.update(per_call({
            f'core {n}': (time.thread_time_ns, 0.0, bare.throw, bare.step),
            f'floor step {n}': (floor_cpu, floor_idle, nothing,
                                functools.partial(floor.step, STEPS)),
            f'floor action {n}': (floor_cpu, floor_idle, nothing,
                                  functools.partial(floor.simulate_steps, STEPS)),
            f'step {n}': (sim_cpu, idle, throw, functools.partial(bench.step, STEPS)),
            f'action {n}': (sim_cpu, idle, throw, functools.partial(bench.simulate_steps, STEPS)),
            f'step {n} one': (sim_cpu, idle, throw, functools.partial(bench.step, 1)),
            f'action {n} one': (sim_cpu, idle, throw, functools.partial(bench.simulate_steps, 1)),
            # As many goals for the floor as for the simulator: a goal's cost grows with the
            # goals whose results a server keeps (goal_result_timeout), so the floor must keep
            # as many.
            f'floor action {n} one': (floor_cpu, floor_idle, nothing,
                                      functools.partial(floor.simulate_steps, 1)),
        }))
        bench.reset()
    # The default ball (a flight order, as the release node sends) and one spawned ball,
    # stepped the same way in the same rounds, each alone in the air.
    bench.set_state(SimulationState.STATE_PAUSED)
    bench.spawn_and_throw(1, eb.LOCK_STEP_LOB)

    def order() -> None:
        bench.reset(ResetSimulation.Request.SCOPE_STATE)  # every ball back at rest
        bench.orders.publish(String(data=FlightOrder.from_release(
            'bench', eb.LOCK_STEP_LOB).to_json()))
        bench.spin(0.5)

    def throw() -> None:
        bench.reset(ResetSimulation.Request.SCOPE_STATE)
        bench.throw(1, eb.LOCK_STEP_LOB)

    step = functools.partial(bench.step, STEPS)
    bare_default, bare_spawned = BareCore(1, default=True), BareCore(1)
    out.update(per_call({
        'core default': (time.thread_time_ns, 0.0, bare_default.throw, bare_default.step),
        'core spawned': (time.thread_time_ns, 0.0, bare_spawned.throw, bare_spawned.step),
        'step default': (sim_cpu, idle, order, step),
        'step spawned': (sim_cpu, idle, throw, step)}))
    bench.reset()
    bench.set_state(SimulationState.STATE_PLAYING)
    return out


def realtime_phase(pid: int, balls: int, seconds: float, subscribed: str) -> dict:
    """Measure the simulator's cores with ``balls`` flying; ``subscribed``: none, tf, all."""
    bench = eb.Bench()
    bench.set_state(SimulationState.STATE_PAUSED)
    bench.reset()
    bench.spawn_and_throw(balls, eb.LOCK_STEP_LOB)
    received = [0]
    if subscribed == 'tf':
        def count(_msg) -> None:
            received[0] += 1
        bench.node.create_subscription(eb.TFMessage, qos.TF, count, qos.TF_QOS, raw=True)
    elif subscribed == 'all':
        _subs, received = bench.count_all(
            balls, lambda k, leaf: qos.TF if k is None else qos.entity_topic(f'b{k}', leaf))
    bench.spin(2.0)  # discovery, and the simulator's turn through the subscriber counts
    bench.set_state(SimulationState.STATE_PLAYING)
    bench.spin(0.5)
    late, skipped = bench.late_ticks()
    received[0] = 0
    cpu, wall = eb.cpu_ns(pid), time.monotonic()
    bench.spin(seconds)
    cpu = (eb.cpu_ns(pid) - cpu) * 1e-9 / (time.monotonic() - wall)
    got = received[0]
    late2, skipped2 = bench.late_ticks()
    per_tick = 1 if subscribed == 'tf' else 2 * balls + 1
    out = {'cores': cpu, 'late': late2 - late, 'skipped': skipped2 - skipped,
           'received': got, 'expected_per_s': 100.0 * per_tick}
    bench.reset()
    return out


def soak_phase(pid: int, balls: int, seconds: float) -> dict:
    """
    RSS growth [MB] and late ticks of the simulator over ``seconds`` with a /tf subscriber.

    ``marks`` holds [time.monotonic() s, late ticks so far] after each re-throw cycle, so that
    the late ticks of loops run beside it can be counted in the same windows (:func:`windows`).
    """
    bench = eb.Bench()
    bench.reset()
    bench.node.create_subscription(eb.TFMessage, qos.TF, lambda _m: None, qos.TF_QOS, raw=True)
    bench.set_state(SimulationState.STATE_PAUSED)
    bench.spawn_and_throw(balls, eb.LOCK_STEP_LOB)
    bench.set_state(SimulationState.STATE_PLAYING)
    bench.spin(5.0)
    rss0 = rss_mb(pid)
    late, skipped = bench.late_ticks()
    marks = [[time.monotonic(), 0]]
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        bench.spin(min(10.0, max(0.0, end - time.monotonic())))
        bench.set_state(SimulationState.STATE_PAUSED)
        bench.throw(balls, eb.LOCK_STEP_LOB)
        bench.set_state(SimulationState.STATE_PLAYING)
        marks.append([time.monotonic(), bench.late_ticks()[0] - late])
    late2, skipped2 = bench.late_ticks()
    return {'rss0': rss0, 'rss1': rss_mb(pid), 'late': late2 - late, 'skipped': skipped2 - skipped,
            'marks': marks}


def steal_phase(seconds: float, every: float = 0.1) -> dict:
    """
    Measure the host's steal time per CPU over ``seconds`` (a hypervisor running other work).

    Read from /proc/stat every ``every`` s; ``late_at`` lists each sample with any steal as
    [time.monotonic() s, CPU, ms stolen since the last sample] (a thread on that CPU, whatever
    its priority, stood still that long), ``total_ms`` per CPU.
    """
    tick_ms = 1000.0 / os.sysconf('SC_CLK_TCK')

    def read() -> dict:
        with open('/proc/stat') as stat:
            return {int(f[0][3:]): int(f[8]) for f in (line.split() for line in stat)
                    if f[0].startswith('cpu') and f[0][3:].isdigit()}

    start = last = read()
    stolen = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        time.sleep(every)
        now = read()
        stolen += [[time.monotonic(), cpu, (n - last[cpu]) * tick_ms]
                   for cpu, n in now.items() if n > last.get(cpu, n)]
        last = now
    return {'late_at': stolen, 'total_ms': {cpu: (n - start[cpu]) * tick_ms
                                            for cpu, n in last.items()}}


def windows(marks: list, loops: list[list], width: float = 60.0) -> list[tuple]:
    """
    Late ticks of the simulator and of each loop per window of about ``width`` s of the soak.

    ``marks``: the soak's [t, simulator's late ticks so far]; ``loops``: each loop's late_at
    ([t, ticks behind]; or any [t, ..., n] list, its last entry summed). The windows end at the
    marks (the simulator's count is read there).
    """
    edges = [marks[0]]
    for mark in marks[1:]:
        if mark[0] - edges[-1][0] >= width - 5.0 or mark is marks[-1]:
            edges.append(mark)
    rows = []
    for (t0, n0), (t1, n1) in zip(edges, edges[1:]):
        rows.append((n1 - n0, *(sum(e[-1] for e in late_at if t0 <= e[0] < t1)
                                for late_at in loops)))
    return rows


def rss_mb(pid: int) -> float:
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1]) / 1024.0
    return float('nan')


def floor_server(executor: str = 'single_threaded') -> None:
    """
    Serve StepSimulation and SimulateSteps answered at once: the do-nothing floor.

    ``executor``: 'single_threaded' (rclpy.spin's, the issue's floor) or 'events' (the
    simulator's default, runner.make_executor).
    """
    import rclpy
    from rclpy.action import ActionServer
    from rclpy.executors import ExternalShutdownException

    from football_ros.nodes.runner import make_executor
    from football_ros.nodes.simulator import PARAMETERS
    from simulation_interfaces.action import SimulateSteps
    from simulation_interfaces.srv import GetSimulationState, ResetSimulation, SetSimulationState
    from simulation_interfaces.srv import StepSimulation

    from simulation_interfaces.msg import Result

    def answer(_request, response):
        response.result.result = Result.RESULT_OK
        return response

    rclpy.init()
    node = rclpy.create_node(FLOOR_NODE.lstrip('/'))
    depth = qos.service_qos()
    for srv_type in (StepSimulation, SetSimulationState, ResetSimulation, GetSimulationState):
        name = {StepSimulation: 'step_simulation', SetSimulationState: 'set_simulation_state',
                ResetSimulation: 'reset_simulation',
                GetSimulationState: 'get_simulation_state'}[srv_type]
        node.create_service(srv_type, f'~/{name}', answer, qos_profile=depth)

    def execute(goal):
        goal.succeed()
        out = SimulateSteps.Result()
        out.result.result = Result.RESULT_OK
        return out

    # The simulator's result timeout (goal_result_timeout): a goal costs more the more goals
    # a server keeps (every status message lists them), so both keep them as long.
    timeout = next(p.default for p in PARAMETERS if p.name == 'goal_result_timeout')
    ActionServer(node, SimulateSteps, '~/simulate_steps', execute_callback=execute,
                 goal_service_qos_profile=depth, result_service_qos_profile=depth,
                 cancel_service_qos_profile=depth, result_timeout=timeout)
    spinner = make_executor(executor)
    spinner.add_node(node)
    print('ready', flush=True)
    try:
        while rclpy.ok():  # as the runner spins (7.1.6's EventsExecutor.spin() busy-waits)
            spinner.spin_once(timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


def phase_process(name: str, **options) -> subprocess.Popen:
    """Start a phase in a fresh client process."""
    argv = [sys.executable, __file__, '--no-record', '--phase', name, '--options',
            json.dumps(options)]
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=REPO)


def phase_result(name: str, proc: subprocess.Popen) -> dict:
    """Wait for a phase's process; return its JSON."""
    try:
        out, err = proc.communicate(timeout=3600)
    finally:
        if proc.poll() is None:
            proc.kill()
    if proc.returncode:
        raise SystemExit(f'phase {name} failed:\n{out}\n{err}')
    return json.loads(out.strip().splitlines()[-1])


def run_phase(name: str, **options) -> dict:
    """Run a phase in a fresh client process; return its JSON."""
    return phase_result(name, phase_process(name, **options))


def start(argv: list[str], log: Path) -> subprocess.Popen:
    proc = subprocess.Popen(argv, stdout=open(log, 'w'), stderr=subprocess.STDOUT, cwd=REPO,
                            env=dict(os.environ, PYTHONPATH=str(REPO)))
    deadline = time.monotonic() + 180.0
    while 'ready' not in log.read_text():
        if proc.poll() is not None or time.monotonic() > deadline:
            raise SystemExit(f'{argv} did not start:\n{log.read_text()}')
        time.sleep(0.1)
    return proc


def stop(proc: subprocess.Popen) -> None:
    proc.send_signal(2)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def simulator(tmp: Path, tag: str, priority: int, executor: str = 'events') -> subprocess.Popen:
    return start([sys.executable, '-m', 'football_ros.cli', 'simulator', '--ros-args', '-p',
                  'publish_rate:=100.0', '-p', 'max_entities:=1000', '-p', 'marker_rate:=0.0',
                  '-p', f'thread_priority:={priority}', '-p', f'executor_type:={executor}'],
                 tmp / f'simulator-{tag}.log')


def lock_step(tmp: Path, draw: int, executor: str, sim: subprocess.Popen,
              balls: list[int]) -> dict:
    """Run the lock-step phase of ``sim`` beside a floor server on the same ``executor``."""
    floor = start([sys.executable, __file__, '--no-record', '--phase', 'floor_server',
                   '--options', json.dumps({'executor': executor})],
                  tmp / f'floor-{draw}-{executor}.log')
    try:
        return run_phase('lockstep', pid=sim.pid, balls=balls, floor_pid=floor.pid)
    finally:
        stop(floor)


def pace_phase(seconds: float, priority: int, work_ms: float = 0.0) -> dict:
    """Run the bare pacing loop at 100 Hz, each tick busy for ``work_ms`` of this thread's CPU."""
    def work(_t: float) -> None:
        end = time.thread_time() + work_ms * 1e-3
        while time.thread_time() < end:
            pass

    return eb.pace(100.0, seconds, priority, work if work_ms > 0.0 else None)


def parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--draws', type=int, default=3)
    parser.add_argument('--hogs', type=int, default=2, help='busy-loop processes beside it')
    parser.add_argument('--balls', type=int, nargs='+', default=[1, 100],
                        help='balls of the lock-step rows')
    parser.add_argument('--rt-balls', type=int, default=999,
                        help='balls of the real-time rows (with the default ball: max_entities)')
    parser.add_argument('--seconds', type=float, default=4.0, help='real-time window [s]')
    parser.add_argument('--soak', type=float, default=600.0, help='soak [s], 0 = none')
    parser.add_argument('--thread-priority', type=int, default=0, choices=range(0, 100),
                        metavar='0-99', help='SCHED_FIFO priority of the pacing threads, 0 = none')
    parser.add_argument('--phase', help=argparse.SUPPRESS)
    parser.add_argument('--options', help=argparse.SUPPRESS, default='{}')
    return parser


def section(priority: int) -> str:
    """Return the RESULTS.md section of a run (one per scheduling of the pacing threads)."""
    title = 'Simulation core (lock-step, real time, soak)'
    return title if not priority else f'{title}, pacing threads on SCHED_FIFO {priority}'


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    if args.phase:
        options = json.loads(args.options)
        if args.phase == 'floor_server':
            floor_server(**options)
            return 0
        fn = {'lockstep': lock_step_phase, 'realtime': realtime_phase, 'soak': soak_phase,
              'pace': pace_phase, 'steal': steal_phase}[args.phase]
        print(json.dumps(fn(**options)))
        return 0
    if any(b < 1 for b in args.balls) or args.rt_balls < 1 or args.draws < 1 or args.hogs < 0:
        parser().error('--balls, --rt-balls and --draws must be >= 1, --hogs >= 0')
    hogs = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
            for _ in range(args.hogs)]
    draws = []
    try:
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            for draw in range(args.draws):
                row = {'physics': bare_tick(args.rt_balls)}
                # The simulator on its classic executor (the lock-step baseline of the same
                # run), then on its default; each beside the do-nothing floor on its executor.
                sim = simulator(tmp, f'{draw}-single', args.thread_priority, 'single_threaded')
                try:
                    row['sim single_threaded'] = lock_step(tmp, draw, 'single_threaded', sim,
                                                           args.balls)
                finally:
                    stop(sim)
                sim = simulator(tmp, str(draw), args.thread_priority)
                try:
                    row['sim events'] = lock_step(tmp, draw, 'events', sim, args.balls)
                    row['rt'] = {
                        case: run_phase('realtime', pid=sim.pid, balls=n,
                                        seconds=args.seconds, subscribed=case.split()[1])
                        for case, n in ((f'{args.rt_balls} tf', args.rt_balls),
                                        (f'{args.rt_balls} none', args.rt_balls),
                                        (f'{ALL_BALLS} all', ALL_BALLS),
                                        (f'{SOAK_BALLS} tf', SOAK_BALLS))
                    }
                    # The publishing floor of the all-subscribed row: the same messages encoded
                    # and published to a client subscribed to all, no simulation, no executor.
                    row['publish floor'] = eb.floor(100.0, ALL_BALLS, args.seconds,
                                                    args.thread_priority)
                    if args.soak > 0 and draw == 0:
                        # Beside the soak, two pacing loops: the bare one (no work) and one
                        # whose tick busies its CPU for the simulator's CPU per tick of this
                        # workload (its real-time row just measured): the floor of any loop
                        # doing that much work a tick on this machine, no ROS, one thread.
                        work_ms = row['rt'][f'{SOAK_BALLS} tf']['cores'] * 10.0  # 100 Hz
                        beside = {
                            key: phase_process('pace', seconds=args.soak + 5.0,
                                               priority=args.thread_priority, work_ms=w)
                            for key, w in (('pace', 0.0), ('pace work', work_ms))
                        }
                        beside['steal'] = phase_process('steal', seconds=args.soak + 5.0)
                        row['soak'] = run_phase('soak', pid=sim.pid, balls=SOAK_BALLS,
                                                seconds=args.soak)
                        row.update({key: phase_result(key, p) for key, p in beside.items()})
                        row['pace work']['work_ms'] = work_ms
                finally:
                    stop(sim)
                draws.append(row)
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
    report(draws, args)
    return 0


def _cells(values, fmt='{:.2f}') -> str:
    return ' / '.join(fmt.format(v) for v in values)


def report(draws: list[dict], args) -> None:
    print(f'{args.draws} draws (cells: draw 1 / 2 / ...), {args.hogs} busy-loop processes beside '
          "the benchmark; CPU = the process's user + system time; pacing threads (the "
          "simulator's, the bare loops') on "
          + (f'SCHED_FIFO {args.thread_priority}.' if args.thread_priority
             else 'the normal scheduler.'))
    print()
    print(f'Lock-step, {STEPS} steps of 1 ms per call (CPU ms per call: the median over '
          f'{ROUNDS} rounds of {REPEATS} calls; the floor server and the bare core (its '
          "step_n in the client's thread) measured in the same rounds as the simulator)")
    for executor in EXECUTORS:
        print(f"The simulator's idle CPU ({executor}; cores): playing with nothing in the air "
              + _cells([d[f'sim {executor}']['idle playing'] for d in draws], '{:.4f}')
              + '; paused with a ball in the air (subtracted from its calls) '
              + _cells([d[f'sim {executor}']['idle paused'] for d in draws], '{:.4f}'))
    print("executor: the simulator's executor_type (events: its default; single_threaded: "
          "the classic, the baseline) and the do-nothing floor server's; (simulator - floor) "
          '/ core subtracts the floor on the same executor, (... - classic floor) the '
          "single_threaded one (rclpy.spin: the issue's floor).")
    print('| call | balls | executor | bare core ms | floor ms (do-nothing server) | simulator ms '
          '| simulator / core | (simulator - floor) / core | (simulator - classic floor) / core '
          '| simulator, 1 step ms | (simulator - its 1 step) / core |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for kind, key in (('StepSimulation', 'step'), ('SimulateSteps', 'action')):
        for n in args.balls:
            classic_ms = [d['sim single_threaded'][f'floor {key} {n}'] * 1e3 for d in draws]
            for executor in EXECUTORS:
                sim = [d[f'sim {executor}'] for d in draws]
                core_ms = [x[f'core {n}'] * 1e3 for x in sim]
                floor_ms = [x[f'floor {key} {n}'] * 1e3 for x in sim]
                sim_ms = [x[f'{key} {n}'] * 1e3 for x in sim]
                one_ms = [x[f'{key} {n} one'] * 1e3 for x in sim]
                print(f'| {kind} | {n} | {executor} | {_cells(core_ms, "{:.3f}")} '
                      f'| {_cells(floor_ms)} | {_cells(sim_ms)} '
                      f'| {_cells([s / c for s, c in zip(sim_ms, core_ms)])} '
                      f'| {_cells([(s - f) / c for s, f, c in zip(sim_ms, floor_ms, core_ms)])} '
                      f'| {_cells([(s - f) / c for s, f, c in zip(sim_ms, classic_ms, core_ms)])} '
                      f'| {_cells(one_ms)} '
                      f'| {_cells([(s - o) / c for s, o, c in zip(sim_ms, one_ms, core_ms)])} |')
    if 1 in args.balls:
        for executor in EXECUTORS:
            sim = [d[f'sim {executor}'] for d in draws]
            core_ratio = [x['core default'] / x['core spawned'] for x in sim]
            sim_ratio = [x['step default'] / x['step spawned'] for x in sim]
            print(f'| StepSimulation, the default ball (a flight order) / a spawned ball (ratios)'
                  f' | 1 | {executor} | {_cells(core_ratio)} | | {_cells(sim_ratio)} '
                  '| | | | | |')
    print()
    print(f'Real time at 100 Hz ({args.seconds:g} s windows; cores = simulator CPU s per s)')
    print('| balls | subscribed | cores | late ticks | skipped | messages received / published '
          '| physics share (kernel pass / simulator CPU per tick) |')
    print('|---|---|---|---|---|---|---|')
    for case in draws[0]['rt']:
        n, sub = case.split()
        cores = [d['rt'][case]['cores'] for d in draws]
        late = [d['rt'][case]['late'] for d in draws]
        skipped = [d['rt'][case]['skipped'] for d in draws]
        share = ''
        if sub == 'none' and int(n) == args.rt_balls:
            share = _cells([d['physics'] * 100.0 / d['rt'][case]['cores'] for d in draws])
        delivered = ''
        if sub != 'none':
            delivered = _cells([d['rt'][case]['received'] / (args.seconds
                                * d['rt'][case]['expected_per_s']) for d in draws])
        print(f'| {n} | {sub} | {_cells(cores)} | {_cells(late, "{}")} '
              f'| {_cells(skipped, "{}")} | {delivered} | {share} |')
    floors = [d['publish floor'] for d in draws]
    published = args.seconds * 100.0 * (2 * ALL_BALLS + 1)  # pose + odom a ball, one /tf a tick
    print(f'| {ALL_BALLS} | all, the publishing floor (encode + publish alone, no simulation) '
          f'| {_cells([f["cpu"] / args.seconds for f in floors])} '
          f'| {_cells([f["late"] for f in floors], "{}")} | '
          f'| {_cells([f["received"] / published for f in floors])} | |')
    soak = draws[0].get('soak')
    if soak:
        print()
        print(f'Soak: 100 balls at 100 Hz re-thrown every 10 s, a /tf subscriber, '
              f'{args.soak:g} s')
        work = draws[0]['pace work']
        print('| RSS start MB | RSS end MB | growth MB | late ticks | skipped '
              '| bare pacing loop late ticks (beside it, same run) '
              f"| pacing loop busy {work['work_ms']:.2f} ms a tick (the simulator's CPU per tick "
              'of this workload, its real-time row), late ticks |')
        print('|---|---|---|---|---|---|---|')
        print(f"| {soak['rss0']:.1f} | {soak['rss1']:.1f} | {soak['rss1'] - soak['rss0']:.2f} "
              f"| {soak['late']} | {soak['skipped']} | {draws[0]['pace']['late']} "
              f"| {work['late']} |")
        steal = draws[0]['steal']
        bursts = [[t, 1] for t, _cpu, ms in steal['late_at'] if ms >= 20.0]  # counted
        rows = windows(soak['marks'], [draws[0]['pace']['late_at'], work['late_at'],
                                       steal['late_at'], bursts])
        sim, bare, busy, stolen, burst = zip(*rows)
        print(f'Late ticks per minute of the soak ({len(rows)} windows): simulator '
              f"{', '.join(map(str, sim))}; bare loop {', '.join(map(str, bare))}; busy loop "
              f"{', '.join(map(str, busy))}. Minutes with the simulator at or under the busy "
              f'loop: {sum(r[0] <= r[2] for r in rows)} of {len(rows)}; at or under the bare '
              f'loop: {sum(r[0] <= r[1] for r in rows)} of {len(rows)}')
        total = ', '.join(f'cpu{c} {ms / 1e3:.1f} s'
                          for c, ms in sorted(steal['total_ms'].items()))
        per_minute = ', '.join(f'{ms:.0f}' for ms in stolen)
        print('Host steal time (/proc/stat; a vCPU the hypervisor gave to something else: any '
              f'thread on it stood still, SCHED_FIFO or not): {total} over the soak; per minute '
              f'[ms, all CPUs] {per_minute}; 0.1 s samples with '
              '20 ms or more (2 periods of a 100 Hz loop) stolen from one CPU per minute '
              f"{', '.join(map(str, burst))}; "
              f'minutes with the simulator above the bare loop and none such: '
              f'{sum(r[0] > r[1] and not r[4] for r in rows)} of {len(rows)}')
        if draws[0]['pace']['refused']:
            print(f"The bare loop's SCHED_FIFO was refused: {draws[0]['pace']['refused']}")


if __name__ == '__main__':
    known, _ = parser().parse_known_args()
    raise SystemExit(recorded(section(known.thread_priority), main))
