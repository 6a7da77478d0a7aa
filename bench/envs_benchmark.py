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
Gymnasium environments: the vector env against the raw batch kernel, SimThrow's flat steps.

    .venv/bin/python bench/envs_benchmark.py [--envs 4096] [--draws 5] [--steps 100000]
        [--seconds S] [--naive 300] [--no-record]

1. Throws per second of ``football_ros/Throw-v0``'s vector env (``--envs`` throws per step:
   noise, release states, the kernel, the score, the next targets) against the batch kernel
   alone on the same releases (:func:`football_ros.physics.batch.simulate_batch` on states made
   beforehand), alternated, ``--draws`` draws each, in this process.
2. ``football_ros/SimThrow-v0`` against this package's simulator (a subprocess): ``--steps``
   env steps (episodes of one throw at 50 Hz) in this one process; steps per second and the
   simulator's CPU per step (its threads' /proc schedstat) over the first and the last 1000
   steps, and per tenth of the run.
3. The slowdown of a naive long-lived client (``--naive`` throws per variant, 0: skipped): the
   usual rclpy pattern (``rclpy.spin_until_future_complete(node, future)``) spawning one new
   ball per throw and never deleting it, the same deleting each ball after its throw, and
   reusing one ball but making a new service client per call; wall time and simulator CPU per
   throw (SetEntityState, StepSimulation of 2 s, GetEntityState) over the first and last 50.
"""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')  # before rclpy starts

import football_ros.envs  # noqa: E402
from football_ros.envs.throws import (  # noqa: E402
    flight_states, MAX_TIME, noisy_releases, ThrowTask)
from football_ros.physics.aero import AeroModel  # noqa: E402
from football_ros.physics.batch import simulate_batch  # noqa: E402
from football_ros.physics.presets import get_preset  # noqa: E402
import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402

NOMINAL = np.array([21.6, 30.0, 2.9, 600.0, 0.0, 0.0, 0.0, 0.0])
SIM_TARGET = {'target_distance': (20.0, 30.0), 'target_bearing_deg': (-10.0, 10.0),
              'target_height': (1.0, 1.8)}
WINDOW = 1000


def cpu_ns(pid: int) -> int:
    """CPU time [ns] of every thread of process ``pid`` so far (schedstat)."""
    total = 0
    for task in Path(f'/proc/{pid}/task').iterdir():
        try:
            total += int((task / 'schedstat').read_text().split()[0])
        except (OSError, ValueError, IndexError):
            pass
    return total


def throughput(n: int, draws: int) -> None:
    """Section 1: the vector env vs the raw kernel, alternated."""
    env = gym.make_vec(football_ros.envs.THROW_ID, num_envs=n,
                       vectorization_mode='vector_entry_point')
    obs, _ = env.reset(seed=0)
    task = ThrowTask()
    rng = np.random.default_rng(0)
    actions = np.tile(NOMINAL, (n, 1))
    ball = get_preset(task.ball)
    env.step(actions)  # compile and warm both paths
    raw_s, env_s = [], []
    for _ in range(draws):
        states = flight_states(task, obs, noisy_releases(task, actions, rng))
        start = time.perf_counter()
        simulate_batch(ball, states, 'full', 'linear', AeroModel(), max_time=MAX_TIME)
        raw_s.append(time.perf_counter() - start)
        start = time.perf_counter()
        obs, *_ = env.step(actions)
        env_s.append(time.perf_counter() - start)
    raw, vec = np.median(raw_s), np.median(env_s)
    print(f'## Throw-v0 vector env vs the batch kernel ({n} throws per call, {draws} draws '
          'each, alternated, median)\n')
    print('| case | s per call | throws/s | of the kernel |')
    print('|---|---|---|---|')
    print(f'| simulate_batch on ready states (baseline) | {raw:.4f} | {n / raw:.0f} | 1.00 |')
    print(f'| ThrowVectorEnv.step | {vec:.4f} | {n / vec:.0f} | {raw / vec:.2f} |')
    print(f'(draws: kernel {", ".join(f"{s:.3f}" for s in raw_s)} s; env '
          f'{", ".join(f"{s:.3f}" for s in env_s)} s)\n')


class Simulator:
    """This package's simulator in a subprocess (its own log), ended by PID."""

    def __init__(self, log_dir: Path, *params: str) -> None:
        self.log = log_dir / f'simulator_{time.monotonic_ns()}.log'
        args = [a for p in params for a in ('-p', p)]
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', 'simulator', '--ros-args', *args],
            stdout=open(self.log, 'w'), stderr=subprocess.STDOUT, cwd=REPO,
            env=dict(os.environ, PYTHONPATH=str(REPO)),
        )
        deadline = time.monotonic() + 300.0
        while 'ready' not in self.log.read_text():
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f'simulator did not start:\n{self.log.read_text()}')
            time.sleep(0.2)

    def stop(self) -> None:
        self.proc.send_signal(2)
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def sim_throw(steps: int, seconds: float, log_dir: Path) -> None:
    """
    Section 2: SimThrow-v0's per-step time and simulator CPU over ``steps`` steps.

    Stops early when ``seconds`` have passed (the steps done are reported).
    """
    sim = Simulator(log_dir)
    try:
        env = gym.make(football_ros.envs.SIM_THROW_ID, simulator='/football_simulator',
                       **SIM_TARGET)
        env.reset(seed=0)
        walls = np.empty(steps)
        cpu = np.empty(steps + 1, dtype=np.int64)  # the simulator's CPU before each step
        episodes = 0
        started = time.monotonic()
        for i in range(steps):
            cpu[i] = cpu_ns(sim.proc.pid)
            start = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(NOMINAL)
            if terminated or truncated:
                env.reset()
                episodes += 1
            walls[i] = time.perf_counter() - start
            if time.monotonic() - started > seconds and i + 1 >= 2 * WINDOW:
                steps = i + 1
                break
        cpu[steps] = cpu_ns(sim.proc.pid)
        walls, cpu = walls[:steps], cpu[:steps + 1]
        total = time.monotonic() - started
        env.close()
    finally:
        sim.stop()
    first, last = walls[:WINDOW], walls[-WINDOW:]
    cpu_first = (cpu[WINDOW] - cpu[0]) * 1e-6 / WINDOW
    cpu_last = (cpu[steps] - cpu[steps - WINDOW]) * 1e-6 / WINDOW
    print(f'## SimThrow-v0 over {steps} steps in one process ({episodes} episodes, 50 Hz '
          f'control, {total:.0f} s{", stopped by --seconds" if total > seconds else ""})\n')
    print('| steps | steps/s | wall ms per step (median) | simulator CPU ms per step |')
    print('|---|---|---|---|')
    print(f'| first {WINDOW} | {WINDOW / first.sum():.1f} | {1e3 * np.median(first):.2f} '
          f'| {cpu_first:.2f} |')
    print(f'| last {WINDOW} | {WINDOW / last.sum():.1f} | {1e3 * np.median(last):.2f} '
          f'| {cpu_last:.2f} |')
    print(f'| last / first | {first.sum() / last.sum():.3f} | '
          f'{np.median(last) / np.median(first):.3f} | {cpu_last / cpu_first:.3f} |')
    tenths = np.array_split(np.arange(steps), 10)
    print('\nper tenth of the run: steps/s '
          + ', '.join(f'{len(t) / walls[t].sum():.1f}' for t in tenths)
          + '; simulator CPU ms per step '
          + ', '.join(f'{(cpu[t[-1] + 1] - cpu[t[0]]) * 1e-6 / len(t):.2f}' for t in tenths)
          + '\n')


def naive(throws: int, log_dir: Path) -> None:
    """Section 3: the naive client's variants (module docstring)."""
    import rclpy
    from simulation_interfaces.msg import Result, SimulationState
    from simulation_interfaces.srv import (DeleteEntity, GetEntityState, SetEntityState,
                                           SetSimulationState, SpawnEntity, StepSimulation)

    from football_ros.envs.sim_throw import release_message

    prefix = '/football_simulator'
    print(f'## A naive long-lived client: {throws} throws per variant\n')
    print('(per throw: SetEntityState, StepSimulation(2000) = 2 s, GetEntityState, with '
          'rclpy.spin_until_future_complete(node, future); simulator CPU from schedstat)\n')
    print('| variant | wall ms per throw, first 50 | last 50 | last / first '
          '| simulator CPU ms, first 50 | last 50 | last / first | client CPU ms, first 50 '
          '| last 50 |')
    print('|---|---|---|---|---|---|---|---|---|')
    state = release_message((0.0, 0.0, 1.8), NOMINAL)
    for variant in ('new ball per throw, never deleted', 'new ball per throw, deleted after',
                    'one ball, a new client per call'):
        sim = Simulator(log_dir, f'max_entities:={throws + 10}')
        rclpy.init()
        node = rclpy.create_node('naive_client')
        clients = {}

        def call(srv_type, name, request, fresh=False):
            client = clients.get(name)
            if client is None or fresh:
                client = node.create_client(srv_type, f'{prefix}/{name}')
                client.wait_for_service(timeout_sec=30.0)
                clients[name] = client
            future = client.call_async(request)
            rclpy.spin_until_future_complete(node, future, timeout_sec=60.0)
            response = future.result()
            if response is None or response.result.result not in (Result.RESULT_OK, 102):
                raise SystemExit(f'{name}: {response}')
            return response

        try:
            call(SetSimulationState, 'set_simulation_state', SetSimulationState.Request(
                state=SimulationState(state=SimulationState.STATE_PAUSED)))
            fresh = variant.startswith('one ball')
            name = call(SpawnEntity, 'spawn_entity',
                        SpawnEntity.Request(name='b0', uri='football_ros://american')).entity_name
            walls, cpus, own = [], [], []
            for k in range(throws):
                cpu0, start, mine = cpu_ns(sim.proc.pid), time.perf_counter(), time.process_time()
                if k and not fresh:
                    name = call(SpawnEntity, 'spawn_entity', SpawnEntity.Request(
                        name=f'b{k}', uri='football_ros://american')).entity_name
                call(SetEntityState, 'set_entity_state',
                     SetEntityState.Request(entity=name, state=state), fresh)
                call(StepSimulation, 'step_simulation', StepSimulation.Request(steps=2000), fresh)
                call(GetEntityState, 'get_entity_state', GetEntityState.Request(entity=name),
                     fresh)
                if variant.endswith('deleted after'):
                    call(DeleteEntity, 'delete_entity', DeleteEntity.Request(entity=name))
                walls.append(time.perf_counter() - start)
                cpus.append(cpu_ns(sim.proc.pid) - cpu0)
                own.append(time.process_time() - mine)
        finally:
            node.destroy_node()
            rclpy.shutdown()
            sim.stop()
        w, c, m = np.array(walls) * 1e3, np.array(cpus) * 1e-6, np.array(own) * 1e3
        wf, wl, cf, cl, mf, ml = (np.median(x) for x in (w[:50], w[-50:], c[:50], c[-50:],
                                                         m[:50], m[-50:]))
        print(f'| {variant} | {wf:.1f} | {wl:.1f} | {wl / wf:.2f} | {cf:.1f} | {cl:.1f} '
              f'| {cl / cf:.2f} | {mf:.1f} | {ml:.1f} |')
    print()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--envs', type=int, default=4096)
    parser.add_argument('--draws', type=int, default=5)
    parser.add_argument('--steps', type=int, default=100_000)
    parser.add_argument('--seconds', type=float, default=math.inf,
                        help='stop the SimThrow run after this long (the steps done are said)')
    parser.add_argument('--naive', type=int, default=300)
    args = parser.parse_args()
    throughput(args.envs, args.draws)
    with tempfile.TemporaryDirectory() as tmp:
        if args.naive:
            naive(args.naive, Path(tmp))
        if args.steps:
            sim_throw(max(args.steps, 2 * WINDOW), args.seconds, Path(tmp))
    return 0


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('envs (Gymnasium)', main))
