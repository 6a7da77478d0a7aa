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
Monte Carlo on Dask: in-process against a local cluster, the per-chunk costs, a scaling model.

    .venv/bin/python bench/montecarlo_scaling.py [--n 10000000] [--workers 2] [--tasks 1000]

1. Throughput in ball-seconds (simulated flight time) per second of wall time at ``--n``
   balls, both runs writing Parquet partitions: in this process (numba's threads on every core,
   the baseline) and on a local cluster of ``--workers`` single-threaded processes, with and
   without the cluster's start (target, issue 24: the cluster >= 90 % of in-process at 10^7).
   Both runs give the same rows (checked through their exact statistics).
2. Per-chunk costs, measured on the cluster: the kernel time of a chunk of 10^4 balls on one
   worker, the worker's time per chunk beside the kernel (sampling, statistics, Parquet, waiting
   for the scheduler: workers x wall / chunks - kernel), the scheduler's cost per task (
   ``--tasks`` no-op tasks at once: wall / tasks, the rate one scheduler sustains), one task's
   round trip, and the client's merge of a chunk's statistics.
3. The scaling model of docs/montecarlo_scaling.md with these numbers: wall time and efficiency
   for 1-1000 workers at 1 and 10 chunks per task.

All in one run on this machine (shared cores: compare ratios, not seconds).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import shutil
import tempfile
import time

from football_ros.physics import Release
from football_ros.tools import mc_engine as eng
from football_ros.tools import montecarlo as mc
import numpy as np


def model(
    n: int, workers: int, chunks_per_task: int, t_kernel: float, o_worker: float,
    o_sched: float, start: float,
) -> tuple[float, float]:
    """
    Wall time [s] and efficiency of ``n`` balls on ``workers`` single-core workers.

    Tasks of ``chunks_per_task`` chunks cost k (t_kernel + o_worker) on a worker; the scheduler
    (and client) handle one task per o_sched. T = start + tasks x max(task / workers, o_sched)
    + one task (the tail); efficiency = kernel time / (workers x T).
    """
    chunks = -(-n // eng.CHUNK)
    tasks = -(-chunks // chunks_per_task)
    task = chunks_per_task * (t_kernel + o_worker)
    wall = start + tasks * max(task / workers, o_sched) + task
    return wall, chunks * t_kernel / (workers * wall)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--n', type=int, default=10_000_000, help='balls per run')
    parser.add_argument('--workers', type=int, default=2, help='local cluster processes')
    parser.add_argument('--tasks', type=int, default=1000, help='no-op tasks for the scheduler')
    args = parser.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix='mc_scaling_'))
    release, spread = Release(), mc.SPREAD_DEFAULTS
    try:
        mc.run(release, 64, spread, 0, progress=False)  # load the kernel here
        inproc = mc.run(release, args.n, spread, 0, False, parquet=tmp / 'a.parquet')
        stored = sum(p.stat().st_size for p in (tmp / 'a.parquet').glob('*.parquet'))
        shutil.rmtree(tmp / 'a.parquet')
        cluster = mc.run(
            release, args.n, spread, 0, False, parquet=tmp / 'b.parquet', workers=args.workers
        )
        shutil.rmtree(tmp / 'b.parquet')
        same = np.array_equal(inproc.stats.mean, cluster.stats.mean) and np.array_equal(
            inproc.stats.m2, cluster.stats.m2
        )
        probe = scheduler_costs(args.workers, args.tasks)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)

    chunks = -(-args.n // eng.CHUNK)
    rate_in = inproc.ball_seconds / inproc.wall
    run_wall = cluster.wall - cluster.start_seconds
    rate_c = cluster.ball_seconds / cluster.wall
    rate_c_run = cluster.ball_seconds / run_wall
    print(
        f'\nMonte Carlo scaling, {args.n} balls ({chunks} chunks of {eng.CHUNK}), '
        f'{os.cpu_count()} cores, Parquet output; same rows in both: {same}\n'
    )
    print(f'{"run":<48}{"wall [s]":>10}{"ball-s/s":>12}{"x in-proc":>11}')
    print(f'{"in-process (baseline, numba on every core)":<48}{inproc.wall:>10.2f}'
          f'{rate_in:>12.4g}{1.0:>11.3f}')
    print(f'{f"local cluster, {args.workers} workers, with its start":<48}{cluster.wall:>10.2f}'
          f'{rate_c:>12.4g}{rate_c / rate_in:>11.3f}')
    print(f'{f"local cluster, {args.workers} workers, after its start":<48}{run_wall:>10.2f}'
          f'{rate_c_run:>12.4g}{rate_c_run / rate_in:>11.3f}')
    print(f'cluster start (processes + kernel load): {cluster.start_seconds:.2f} s; '
          'target: cluster >= 0.90 x in-process')

    t_kernel = cluster.seconds / chunks
    o_worker = max(0.0, args.workers * run_wall / chunks - t_kernel)
    t_kernel_in = inproc.seconds / chunks
    print(f'\n{"per chunk of 10^4 balls":<58}{"time [ms]":>10}')
    for name, sec in [
        ('kernel, one worker (1 thread)', t_kernel),
        ('kernel, in-process (all cores)', t_kernel_in),
        ('worker time beside the kernel (workers x wall / chunks - kernel)', o_worker),
        (f'scheduler per task ({args.tasks} no-op tasks at once)', probe['per_task']),
        ('one task round trip (submit, run, result; 50 in a row)', probe['round_trip']),
        ("client: merge one chunk's statistics", probe['merge']),
    ]:
        print(f'{name:<58}{1e3 * sec:>10.3f}')
    overhead = o_worker / (t_kernel + o_worker)
    print(f'per-chunk overhead share on a worker: {100 * overhead:.1f} %')
    per_ball = stored / args.n
    print(
        f'Parquet: {per_ball:.1f} bytes per ball; one worker writes '
        f'{per_ball * eng.CHUNK / (t_kernel + o_worker) / 1e6:.2f} MB/s, 100 workers '
        f'{100 * per_ball * eng.CHUNK / (t_kernel + o_worker) / 1e6:.0f} MB/s'
    )

    o_sched = probe['per_task'] + probe['merge']
    print('\nscaling model (docs/montecarlo_scaling.md): T = start + tasks x max(task / W, '
          'scheduler per task) + task')
    print(f'{"workers":>8}{"chunks/task":>13}{"10^8 balls [s]":>16}{"eff.":>7}'
          f'{"10^10 balls [s]":>17}{"eff.":>7}')
    for workers in (1, 2, 10, 100, 1000):
        for k in (1, 10):
            w8, e8 = model(10**8, workers, k, t_kernel, o_worker, o_sched, cluster.start_seconds)
            w10, e10 = model(
                10**10, workers, k, t_kernel, o_worker, o_sched, cluster.start_seconds
            )
            print(f'{workers:>8}{k:>13}{w8:>16.1f}{100 * e8:>6.0f}%{w10:>17.0f}{100 * e10:>6.0f}%')
    print(f'the scheduler saturates at W = task / scheduler per task = '
          f'{(t_kernel + o_worker) / o_sched:.0f} workers (1 chunk per task), '
          f'{10 * (t_kernel + o_worker) / o_sched:.0f} (10 chunks per task)')


def scheduler_costs(workers: int, tasks: int) -> dict[str, float]:
    """No-op tasks on a fresh local cluster; the client's merge of chunk statistics."""
    from dask.distributed import wait

    with eng.Engine(workers=workers) as engine:
        client = engine.client
        wait(client.map(abs, range(-50, 0), pure=False))  # warm the connections
        begin = time.perf_counter()
        futures = client.map(abs, range(tasks), pure=False)
        wait(futures)
        per_task = (time.perf_counter() - begin) / tasks
        del futures
        begin = time.perf_counter()
        for i in range(50):
            client.submit(abs, -i, pure=False).result()
        round_trip = (time.perf_counter() - begin) / 50
    plan = eng.Plan(Release(), mc.as_spread(mc.SPREAD_DEFAULTS), 0, eng.CHUNK, None, None, 10)
    chunk = eng.run_chunk(plan, 0).stats
    total = eng.Stats()
    begin = time.perf_counter()
    for _ in range(1000):
        total.merge(chunk)
    merge = (time.perf_counter() - begin) / 1000
    return {'per_task': per_task, 'round_trip': round_trip, 'merge': merge}


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('Monte Carlo scaling', main))
