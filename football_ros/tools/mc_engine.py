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
Monte Carlo engine: chunks of balls, seeded one by one, flown here or on a Dask cluster.

Seeding: chunk ``i`` (balls ``i * CHUNK`` to ``(i + 1) * CHUNK - 1``) draws one row of
:data:`INPUT_KEYS` standard normals per ball from
``numpy.random.SeedSequence(seed, spawn_key=(i,))``, which is ``SeedSequence(seed).spawn(i +
1)[i]``; every input is a transform of its own column (:func:`sample_chunk`), and each chunk is
integrated by its own :func:`football_ros.physics.batch.simulate_batch` call (the batch kernel
groups balls of similar step inside a call, so a ball's numbers depend on the other balls of its
call). A row therefore depends on the seed and its ball index only: not on the number of
workers, of chunks per task, on the order the chunks finish, nor on ``--n`` (the first n balls
of a longer run are the shorter run's).

Execution (:class:`Engine`): in-process (numba's threads on every core), on a local Dask cluster
of N single-threaded worker processes (127.0.0.1, no dashboard), or on an existing cluster by
address. Inside a Dask task numba runs one thread (no oversubscription next to the other
workers); with a threading layer that is not thread-safe (numba's ``workqueue``), the kernel
calls of one worker process's task threads are serialised by a lock.

Results of a chunk: :class:`Stats` (counts, the exact mean and covariance of the inputs and the
landing point, a deterministic subsample for quantiles and the figure) and either its rows
(gathered by the client for CSV/.npz) or nothing (the task wrote them as a Parquet partition
``part-<first chunk>.parquet``, one row group per chunk, in the output folder, which the
workers must reach).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
import math
import os
from pathlib import Path
import threading
import time
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np

from ..physics import Release
from ..physics.release import LIMITS, STATE_KEYS

INPUT_KEYS = STATE_KEYS
"""The sampled release quantities (units in the name; speed m/s), in their column order."""
OUTPUT_KEYS = (
    'landing_x',
    'landing_y',
    'time_of_flight',
    'landed',
    'max_alpha_deg',
    'max_beta_deg',
    'max_delta_deg',
    'stable',
    'clipped',
)
COLUMNS = (*INPUT_KEYS, *OUTPUT_KEYS)
"""Per-ball columns: release (units in the name; speed m/s), landing_x/y [m], time_of_flight [s],
landed (0/1), the largest |alpha|, |beta| and delta over the flight [deg], stable (0/1:
gyroscopically stable at release, spin above the critical spin), clipped (0/1: an input was
clipped into its accepted range)."""
SUMMARY_KEYS = (
    'landing_x',
    'landing_y',
    'time_of_flight',
    'landed',
    'max_alpha_deg',
    'max_beta_deg',
    'max_delta_deg',
)
"""Columns of the subsample the summary table and the figure use."""
MOMENT_KEYS = (*INPUT_KEYS, 'landing_x', 'landing_y', 'time_of_flight')
"""Quantities whose exact mean and covariance (over landed balls) every run accumulates."""
CHUNK = 10_000
"""Balls per chunk: the unit of seeding and of integration (0.1-0.2 s of kernel per core)."""
CLOSE_TIMEOUT_S = 30.0
"""Longest wait [s] for the Dask client and a local cluster to close."""
SUBSAMPLE_TOTAL = 1_000_000
"""Rows kept for quantiles and the figure when the rows themselves are not gathered."""
DISTRIBUTIONS = ('normal', 'uniform', 'lognormal')


@dataclass(frozen=True)
class Spread:
    """
    The error of one input around its nominal value.

    ``normal``: nominal + width * z (width = sigma); ``uniform``: nominal + width * (2 Phi(z) -
    1), uniform in [nominal - width, nominal + width]; ``lognormal``: nominal * exp(width * z)
    (median the nominal, sign kept; width = sigma of ln|x|). z is the input's standard normal.
    """

    dist: str = 'normal'
    width: float = 0.0

    def __post_init__(self) -> None:
        if self.dist not in DISTRIBUTIONS:
            raise ValueError(f"distribution must be one of {', '.join(DISTRIBUTIONS)}")
        if not math.isfinite(self.width) or self.width < 0:
            raise ValueError(f'width must be a finite number >= 0, got {self.width}')

    def describe(self, unit: str) -> str:
        """Human-readable form, e.g. ``N(0, 0.5) m/s``."""
        if self.dist == 'normal':
            return f'normal, sigma {self.width:g} {unit}'.rstrip()
        if self.dist == 'uniform':
            return f'uniform, +-{self.width:g} {unit}'.rstrip()
        return f'log-normal, sigma of ln {self.width:g}'


@dataclass(frozen=True)
class Plan:
    """Everything a chunk needs (sent to the workers): release, errors, seed, outputs."""

    release: Release
    spread: Mapping[str, Spread]
    seed: int
    n: int
    """Balls (the most, with a stopping rule)."""
    zone: tuple[float, float, float] | None = None
    """(x, y, r) [m] on the ground in ``field``: a ball lands in it within r of (x, y)."""
    parquet: str | None = None
    """Folder the tasks write their partitions to; None = the rows go back to the client."""
    subsample: int = CHUNK
    """Rows of each chunk kept in its Stats (all of them when the rows are gathered)."""
    chunk: int = CHUNK
    gather: bool = True
    """Without Parquet: send the rows back (False: statistics only, the rows dropped)."""

    @property
    def n_chunks(self) -> int:
        return (self.n + self.chunk - 1) // self.chunk

    def count(self, index: int) -> int:
        """Balls in chunk ``index``."""
        return max(0, min(self.chunk, self.n - index * self.chunk))


@dataclass
class Stats:
    """Mergeable statistics of a set of balls (exact, except the subsample: its first rows)."""

    n: int = 0
    landed: int = 0
    unstable: int = 0
    clipped: np.ndarray = field(default_factory=lambda: np.zeros(len(INPUT_KEYS), np.int64))
    any_clipped: int = 0
    in_zone: int = 0
    count: int = 0
    """Landed balls in the moments."""
    mean: np.ndarray = field(default_factory=lambda: np.zeros(len(MOMENT_KEYS)))
    m2: np.ndarray = field(default_factory=lambda: np.zeros((len(MOMENT_KEYS),) * 2))
    """Sum of the outer products of the deviations from the mean (Chan et al.)."""
    subsample: dict[str, list] = field(default_factory=lambda: {k: [] for k in SUMMARY_KEYS})

    @classmethod
    def of(cls, rows: Mapping[str, np.ndarray], zone, keep: int) -> 'Stats':
        """Return the statistics of one chunk's rows, keeping its first ``keep`` rows."""
        landed = rows['landed'].astype(bool)
        values = np.column_stack([rows[k][landed] for k in MOMENT_KEYS])
        mean = values.mean(axis=0) if values.shape[0] else np.zeros(len(MOMENT_KEYS))
        dev = values - mean
        in_zone = 0
        if zone is not None:
            x, y, r = zone
            d2 = (rows['landing_x'] - x) ** 2 + (rows['landing_y'] - y) ** 2
            in_zone = int(np.count_nonzero(landed & (d2 <= r * r)))
        return cls(
            n=int(landed.size),
            landed=int(landed.sum()),
            unstable=int(np.count_nonzero(rows['stable'] == 0)),
            clipped=np.asarray(rows['_clipped_by_key'], np.int64),
            any_clipped=int(np.count_nonzero(rows['clipped'])),
            in_zone=in_zone,
            count=int(values.shape[0]),
            mean=mean,
            m2=dev.T @ dev,
            subsample={k: [np.array(rows[k][:keep])] for k in SUMMARY_KEYS},
        )

    def merge(self, other: 'Stats') -> None:
        """Add ``other``'s balls to these (in place)."""
        self.n += other.n
        self.landed += other.landed
        self.unstable += other.unstable
        self.clipped = self.clipped + other.clipped
        self.any_clipped += other.any_clipped
        self.in_zone += other.in_zone
        total = self.count + other.count
        if other.count:
            delta = other.mean - self.mean
            weight = self.count * other.count / total
            self.m2 = self.m2 + other.m2 + np.outer(delta, delta) * weight
            self.mean = self.mean + delta * other.count / total
            self.count = total
        for k in SUMMARY_KEYS:
            self.subsample[k].extend(other.subsample[k])

    def covariance(self) -> np.ndarray:
        """Covariance of :data:`MOMENT_KEYS` over the landed balls (population, 1/N)."""
        return self.m2 / max(self.count, 1)

    def sample(self) -> dict[str, np.ndarray]:
        """Return the subsample as arrays (the first rows of every chunk, in ball order)."""
        return {
            k: (np.concatenate(v) if v else np.zeros(0)) for k, v in self.subsample.items()
        }


@dataclass
class ChunkResult:
    """One chunk: its index, statistics, rows (None if written to Parquet), kernel seconds."""

    index: int
    stats: Stats
    rows: dict[str, np.ndarray] | None
    seconds: float
    ball_seconds: float
    threads: int = 0
    """Numba threads the kernel ran on."""
    pid: int = 0
    """Process that flew it."""


def chunk_seed(seed: int, index: int) -> np.random.SeedSequence:
    """Return chunk ``index``'s SeedSequence: ``SeedSequence(seed).spawn(index + 1)[index]``."""
    return np.random.SeedSequence(seed, spawn_key=(index,))


def sample_chunk(
    release: Release, spread: Mapping[str, Spread], seed: int, index: int, count: int
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """
    Draw the inputs of chunk ``index``'s first ``count`` balls; which were clipped.

    Returns {key: values (units of the key)} and a (count, len(INPUT_KEYS)) bool array: True
    where the drawn value left :data:`football_ros.physics.release.LIMITS` and was clipped into
    it (and the elevation of a ground release below 0.5 deg: it must go up).
    """
    rng = np.random.default_rng(chunk_seed(seed, index))
    z = rng.standard_normal((count, len(INPUT_KEYS)))  # ball by ball: a prefix is stable
    out, clipped = {}, np.zeros((count, len(INPUT_KEYS)), bool)
    for j, key in enumerate(INPUT_KEYS):
        s = spread[key]
        nominal = float(getattr(release, key))
        if s.dist == 'normal':
            value = nominal + s.width * z[:, j]
        elif s.dist == 'uniform':
            from scipy.special import ndtr

            value = nominal + s.width * (2.0 * ndtr(z[:, j]) - 1.0)
        else:
            value = nominal * np.exp(s.width * z[:, j])
        lo, hi = LIMITS[key]
        if key == 'elevation_deg' and release.position[2] <= 0.0:
            lo = 0.5
        clipped[:, j] = (value < lo) | (value > hi)
        out[key] = np.clip(value, lo, hi)
    return out, clipped


def fly(release: Release, samples: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """
    Fly one set of sampled releases (one simulate_batch call); the output columns.

    Returns landing_x/y [m], time_of_flight [s], landed (int8), max_alpha/beta/delta_deg
    [deg], stable (int8: h1^2 > 4 M_alpha at release, with the air-relative speed).
    """
    from ..physics.aero import resolve
    from ..physics.batch import simulate_batch
    from ..physics.release import release_states

    states = release_states(
        *(samples[k] for k in INPUT_KEYS), np.array(release.position, dtype=float)
    )
    aero = release.aero_model()
    result = simulate_batch(release.preset(), states, release.model, release.moment, aero)
    ball, aero = resolve(release.preset(), release.model, aero)
    wind = np.array(aero.wind) if aero is not None else np.zeros(3)
    air2 = np.sum((states['velocity'] - wind) ** 2, axis=1)
    h1 = ball.inertia_ratio * states['spin']
    return {
        'landing_x': result.landing_x,
        'landing_y': result.landing_y,
        'time_of_flight': result.time_of_flight,
        'landed': result.landed.astype(np.int8),
        'max_alpha_deg': np.degrees(result.max_alpha),
        'max_beta_deg': np.degrees(result.max_beta),
        'max_delta_deg': np.degrees(result.max_delta),
        'stable': (h1 * h1 > 4.0 * ball.moment_coefficient() * air2).astype(np.int8),
    }


_KERNEL_LOCK = threading.Lock()
_THREAD_SAFE: bool | None = None  # numba's threading layer, once known


def _kernel_guard():
    """Return a lock around the kernel unless numba's threading layer is thread-safe (omp, tbb)."""
    return contextlib.nullcontext() if _THREAD_SAFE else _KERNEL_LOCK


def run_chunk(plan: Plan, index: int) -> ChunkResult:
    """Sample and fly chunk ``index``; its statistics and rows."""
    global _THREAD_SAFE
    count = plan.count(index)
    samples, clipped = sample_chunk(plan.release, plan.spread, plan.seed, index, count)
    with _kernel_guard():
        begin = time.perf_counter()
        out = fly(plan.release, samples)
        seconds = time.perf_counter() - begin
        import numba

        threads = numba.get_num_threads()
        if _THREAD_SAFE is None:
            _THREAD_SAFE = numba.threading_layer() in ('omp', 'tbb')
    rows = {**samples, **out, 'clipped': clipped.any(axis=1).astype(np.int8)}
    rows['_clipped_by_key'] = clipped.sum(axis=0)
    stats = Stats.of(rows, plan.zone, plan.subsample)
    del rows['_clipped_by_key']
    ball_seconds = float(out['time_of_flight'].sum())
    return ChunkResult(index, stats, rows, seconds, ball_seconds, threads, os.getpid())


def warm_up(parquet: bool = False) -> str:
    """Load the batch kernel (one ball, one numba thread) and pyarrow; the threading layer."""
    import numba

    if parquet:
        import pyarrow.parquet  # noqa: F401

    numba.set_num_threads(1)
    with _kernel_guard():
        fly(Release(), {k: np.array([float(getattr(Release(), k))]) for k in INPUT_KEYS})
    return numba.threading_layer()


def partition_path(folder: str | Path, first: int) -> Path:
    """Return the Parquet partition of the task whose first chunk is ``first``."""
    return Path(folder) / f'part-{first:08d}.parquet'


def run_task(
    plan: Plan, first: int, last: int, threads: int | None = None
) -> list[ChunkResult]:
    """
    Run chunks ``first`` .. ``last - 1`` (a Dask task, or a step of the in-process loop).

    ``threads``: numba threads for the kernel (None = as set). With ``plan.parquet`` the rows
    are written to the task's partition (one row group per chunk) and not returned; without
    it they are returned if ``plan.gather``.
    """
    if threads is not None:
        import numba

        numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    results = [run_chunk(plan, i) for i in range(first, last)]
    if plan.parquet is None and not plan.gather:
        for r in results:
            r.rows = None
    if plan.parquet is not None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        path = partition_path(plan.parquet, first)
        tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
        writer = None
        try:
            for r in results:
                table = pa.table({k: r.rows[k] for k in COLUMNS})
                if writer is None:
                    writer = pq.ParquetWriter(tmp, table.schema, compression='snappy')
                writer.write_table(table)
                r.rows = None
        finally:
            if writer is not None:
                writer.close()
        os.replace(tmp, path)
    return results


def tasks(n_chunks: int, task_chunks: int) -> list[tuple[int, int]]:
    """(first, last) chunk ranges of ``task_chunks`` chunks each."""
    step = max(1, task_chunks)
    return [(i, min(i + step, n_chunks)) for i in range(0, n_chunks, step)]


@contextlib.contextmanager
def _deferred_interrupt():
    """Hold a SIGINT (Ctrl-C) back until the block ends, then raise KeyboardInterrupt."""
    import signal

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda *_: caught.append(True))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt


class Engine:
    """
    Where chunks run: in this process, a local Dask cluster, or an existing one.

    A context manager: the cluster and client it starts are closed on exit.
    """

    def __init__(
        self, workers: int | None = None, scheduler: str | None = None, parquet: bool = False
    ) -> None:
        if workers is not None and scheduler is not None:
            raise ValueError('--workers and --scheduler exclude each other')
        self.workers, self.scheduler, self.parquet = workers, scheduler, parquet
        self.client = self.cluster = None
        self.start_seconds = 0.0

    @property
    def distributed(self) -> bool:
        return self.workers is not None or self.scheduler is not None

    def __enter__(self) -> 'Engine':
        if not self.distributed:
            return self
        import logging

        from dask.distributed import Client, LocalCluster

        begin = time.perf_counter()
        try:
            if self.scheduler is not None:
                try:
                    self.client = Client(self.scheduler, timeout='20s')
                except (OSError, TimeoutError, ValueError) as exc:
                    raise OSError(f'--scheduler {self.scheduler}: {exc}') from None
            else:
                with _deferred_interrupt():  # a Ctrl-C here must not orphan a half-made cluster
                    self.cluster = LocalCluster(
                        n_workers=self.workers,
                        threads_per_worker=1,
                        processes=True,
                        host='127.0.0.1',
                        dashboard_address='127.0.0.1:0',  # HTTP server: loopback, a free port
                        worker_dashboard_address=None,
                        silence_logs=logging.CRITICAL,  # not the shutdown races
                        env={'NUMBA_NUM_THREADS': '1', 'OMP_NUM_THREADS': '1'},
                    )
                self.client = Client(self.cluster)
                self.client.wait_for_workers(self.workers, timeout=120)
            # numba's kernel (and pyarrow) loaded before the clock of any chunk
            self.client.run(warm_up, self.parquet)
        except BaseException:
            self.close()
            raise
        self.start_seconds = time.perf_counter() - begin
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """
        Close the client and the local cluster (if any), within CLOSE_TIMEOUT_S.

        Dask waits for ever by default for a worker that does not close (one still starting on
        a loaded machine, say); past the bound the worker processes, daemonic children of this
        one, are ended when it exits.
        """
        client, cluster, self.client, self.cluster = self.client, self.cluster, None, None
        try:
            if client is not None:
                with contextlib.suppress(TimeoutError):
                    client.close(timeout=CLOSE_TIMEOUT_S)
        finally:
            if cluster is not None:
                with contextlib.suppress(TimeoutError):
                    cluster.close(timeout=CLOSE_TIMEOUT_S)

    def n_workers(self) -> int:
        """Workers now connected (1 in-process)."""
        if self.client is None:
            return 1
        return len(self.client.scheduler_info().get('workers', {})) or 1

    def results(self, plan: Plan, task_chunks: int = 1) -> Iterator[ChunkResult]:
        """
        Chunk results in index order (a generator).

        Closed early, it lets the queued tasks end (a stopping rule); an exception thrown in
        cancels them (a Ctrl-C or an error of the consumer).

        Dask: at most 2 W + 2 tasks (W workers) running, queued or finished and waiting for an
        earlier one, so that a stopping rule wastes little and the client holds few results,
        even when one task is slow.
        """
        ranges = tasks(plan.n_chunks, task_chunks)
        if self.client is None:
            for first, last in ranges:
                yield from run_task(plan, first, last)
            return
        from dask.distributed import as_completed

        ahead = 2 * self.n_workers() + 2
        pending = iter(ranges)
        futures = as_completed()
        live = []

        ready: dict[int, list[ChunkResult]] = {}  # first chunk -> a finished task's results

        def top_up() -> None:
            while len(live) + len(ready) < ahead:
                nxt = next(pending, None)
                if nxt is None:
                    return
                fut = self.client.submit(
                    run_task, plan, nxt[0], nxt[1], 1, pure=False, priority=-nxt[0]
                )
                futures.add(fut)
                live.append(fut)

        top_up()
        want = 0
        try:
            for fut in futures:
                done = fut.result()
                ready[done[0].index] = done
                live.remove(fut)
                fut.release()
                while want in ready:
                    for r in ready.pop(want):
                        yield r
                        want = r.index + 1
                top_up()
        except GeneratorExit:  # a stopping rule: let the queued tasks end (their partitions
            if live:  # are removed after them); at most `ahead` tasks
                from dask.distributed import wait

                wait(live, timeout=600)
            raise
        finally:
            if live:
                self.client.cancel(live)


def wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float, float]:
    """Return k/n and its Wilson score interval (95 % for the default z): (p, low, high)."""
    if n <= 0:
        return math.nan, 0.0, 1.0
    p = k / n
    z2n = z * z / n
    centre = (p + z2n / 2.0) / (1.0 + z2n)
    half = z / (1.0 + z2n) * math.sqrt(p * (1.0 - p) / n + z2n / (4.0 * n))
    return p, max(0.0, centre - half), min(1.0, centre + half)


def ellipse(cov: np.ndarray, level: float) -> tuple[float, float, float]:
    """
    Semi-axes [m] and orientation of the ``level`` ellipse of a 2-D Gaussian of covariance cov.

    Returns (major, minor, angle [rad, of the major axis from +x toward +y]); the ellipse holds
    ``level`` of the probability: r^2 = -2 ln(1 - level) in Mahalanobis units.
    """
    values, vectors = np.linalg.eigh(cov)
    r2 = -2.0 * math.log(1.0 - level)
    major, minor = (math.sqrt(max(v, 0.0) * r2) for v in values[::-1])
    angle = math.atan2(vectors[1, 1], vectors[0, 1])
    if angle > math.pi / 2:
        angle -= math.pi
    elif angle <= -math.pi / 2:
        angle += math.pi
    return major, minor, angle


def inside_ellipse(x, y, mean, cov, level: float) -> np.ndarray:
    """Whether points (x, y) [m] lie inside the ``level`` ellipse of (mean, cov)."""
    d = np.column_stack([np.asarray(x) - mean[0], np.asarray(y) - mean[1]])
    m2 = np.einsum('ij,jk,ik->i', d, np.linalg.pinv(cov), d)
    return m2 <= -2.0 * math.log(1.0 - level)


def sensitivity(stats: Stats, output: str) -> list[tuple[str, float, float]]:
    """
    Which input drives ``output``: (input, slope, share of the variance) per sampled input.

    The slope [output unit per input unit] is the least-squares fit of the output on all the
    inputs with a spread; the share is slope^2 var(input) / var(output), the first-order
    (linear) variance share of an independent input. The shares add up to the fit's R^2 (1
    for a linear response).
    """
    cov = stats.covariance()
    j = MOMENT_KEYS.index(output)
    idx = [i for i, k in enumerate(INPUT_KEYS) if cov[i, i] > 0.0]
    if not idx or cov[j, j] <= 0.0:
        return []
    sxx = cov[np.ix_(idx, idx)]
    sxy = cov[idx, j]
    slope = np.linalg.lstsq(sxx, sxy, rcond=None)[0]
    var_in = np.diag(sxx)
    return [
        (INPUT_KEYS[i], float(b), float(b * b * v / cov[j, j]))
        for i, b, v in zip(idx, slope, var_in)
    ]


def fit_r2(stats: Stats, output: str) -> float:
    """R^2 of the least-squares fit of :func:`sensitivity` (explained share of the variance)."""
    cov = stats.covariance()
    j = MOMENT_KEYS.index(output)
    idx = [i for i, k in enumerate(INPUT_KEYS) if cov[i, i] > 0.0]
    if not idx or cov[j, j] <= 0.0:
        return math.nan
    slope = np.linalg.lstsq(cov[np.ix_(idx, idx)], cov[idx, j], rcond=None)[0]
    return float(slope @ cov[idx, j] / cov[j, j])


class _Abandoned(Exception):
    """Thrown into :meth:`Engine.results` when its consumer fails: cancel, do not wait."""


def drain(
    engine: Engine,
    plan: Plan,
    task_chunks: int = 1,
    on_chunk: Callable[[ChunkResult, Stats], bool] | None = None,
) -> tuple[Stats, list[dict[str, np.ndarray]], float, float, int]:
    """
    Run a plan; merge the chunks in index order.

    ``on_chunk(result, stats so far)`` is called after each chunk; True stops the run there
    (the chunks after it are cancelled, their partitions removed). Returns (stats, the chunks'
    rows in order, kernel seconds, ball-seconds flown, chunks used).
    """
    stats = Stats()
    rows: list[dict[str, np.ndarray]] = []
    seconds = ball_seconds = 0.0
    used = 0
    gen = engine.results(plan, task_chunks)
    try:
        for r in gen:
            stats.merge(r.stats)
            seconds += r.seconds
            ball_seconds += r.ball_seconds
            used = r.index + 1
            if r.rows is not None:
                rows.append(r.rows)
            if on_chunk is not None and on_chunk(r, stats):
                break
    except BaseException:
        # A Ctrl-C or an error here: the running tasks are cancelled, not waited for (closing
        # the generator would wait for them, as a stopping rule wants).
        with contextlib.suppress(_Abandoned):
            gen.throw(_Abandoned())
        raise
    finally:
        gen.close()
    if plan.parquet is not None and used < plan.n_chunks:
        remove_partitions(plan.parquet, first=used)
    return stats, rows, seconds, ball_seconds, used


def remove_partitions(folder: str | Path, first: int = 0) -> None:
    """Remove the partitions (and stale temporary files) from chunk ``first`` on."""
    for path in Path(folder).glob('part-*.parquet'):
        try:
            index = int(path.stem.split('-')[1])
        except (IndexError, ValueError):
            continue
        if index >= first:
            path.unlink()
    if first == 0:
        for path in Path(folder).glob('.part-*.tmp'):
            path.unlink()


def concat(rows: Sequence[Mapping[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Return the gathered chunks' rows as one table in :data:`COLUMNS` order."""
    if not rows:
        return {k: np.zeros(0) for k in COLUMNS}
    return {k: np.concatenate([r[k] for r in rows]) for k in COLUMNS}
