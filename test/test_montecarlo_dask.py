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
Monte Carlo on Dask: the same rows whatever the workers, Parquet, numba's threads in workers.

Every cluster here is small (1-4 processes), on 127.0.0.1 without a dashboard, and closed in a
``finally``; every run is bounded by a timeout.
"""

import logging
import os
import subprocess
import sys

from football_ros.physics import Release
from football_ros.tools import mc_engine as eng
from football_ros.tools import montecarlo as mc
import numpy as np
import pytest

N = 25_000  # three chunks, the last one partial
ZONE = (66.0, 0.0, 3.0)


def _cli(*args, timeout=240):
    proc = subprocess.run(
        [sys.executable, '-m', 'football_ros.cli', 'montecarlo', '--quiet', *args],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert proc.returncode == 0, proc.stderr
    return proc


@pytest.fixture(scope='module')
def cluster():
    """Start a local cluster of 2 worker processes with 2 task threads each."""
    from dask.distributed import LocalCluster

    local = LocalCluster(
        n_workers=2,
        threads_per_worker=2,
        processes=True,
        host='127.0.0.1',
        dashboard_address='127.0.0.1:0',
        silence_logs=logging.ERROR,
    )
    try:
        yield local.scheduler_address
    finally:
        local.close()


@pytest.fixture(scope='module')
def reference():
    """Fly the in-process rows of the runs below."""
    return mc.run(Release(), N, mc.SPREAD_DEFAULTS, 11, progress=False, zone=ZONE)


def test_workers_1_2_4_write_the_same_rows_bit_for_bit(reference, tmp_path):
    common = ('--n', str(N), '--seed', '11', '--figure', 'none')
    _cli(*common, '--out', str(tmp_path / 'ref.csv'))
    _cli(*common, '--workers', '1', '--out', str(tmp_path / 'w1.csv'))
    out = _cli(*common, '--workers', '2', '--out', str(tmp_path / 'w2.csv')).stdout
    assert 'on 2 Dask worker(s)' in out
    _cli(*common, '--workers', '2', '--out', str(tmp_path / 'w2.npz'))
    _cli(*common, '--workers', '4', '--task-chunks', '2', '--out', str(tmp_path / 'w4.npz'))
    ref = (tmp_path / 'ref.csv').read_bytes()
    assert ref.count(b'\n') == N + 1
    assert (tmp_path / 'w1.csv').read_bytes() == ref
    assert (tmp_path / 'w2.csv').read_bytes() == ref
    a = reference.rows  # in-process, in this process
    with np.load(tmp_path / 'w2.npz') as b, np.load(tmp_path / 'w4.npz') as c:
        assert list(a) == list(mc.COLUMNS) == b.files == c.files
        for key in a:
            assert np.array_equal(a[key], b[key]) and np.array_equal(a[key], c[key]), key
        # And the rows are physics: the landing of the paper model is the vacuum range.
        v, th = a['speed'], np.radians(a['elevation_deg'])
        x = v**2 * np.sin(2 * th) / 9.81 * np.cos(np.radians(a['azimuth_deg']))
        assert np.allclose(a['landing_x'], x, atol=1e-5)


def test_parquet_on_an_existing_cluster(cluster, reference, tmp_path):
    """Workers write the partitions; the client holds statistics only; lazy loading."""
    import pyarrow.dataset as ds

    folder = tmp_path / 'mc.parquet'
    seen = []
    plan = eng.Plan(
        Release(), mc.as_spread(mc.SPREAD_DEFAULTS), 11, N, ZONE, str(folder), subsample=100
    )
    folder.mkdir()
    with eng.Engine(scheduler=cluster) as engine:
        stats, rows, *_ = eng.drain(engine, plan, 1, lambda r, s: seen.append(r) and False)
    assert rows == [] and all(r.rows is None for r in seen)
    assert [r.index for r in seen] == [0, 1, 2]
    # numba runs one thread inside a task: two task threads per worker, no oversubscription.
    assert all(r.threads == 1 for r in seen) and os.getpid() not in {r.pid for r in seen}
    parts = sorted(p.name for p in folder.glob('*.parquet'))
    assert parts == ['part-00000000.parquet', 'part-00000001.parquet', 'part-00000002.parquet']
    data = ds.dataset(folder, format='parquet')
    assert data.count_rows() == N and data.schema.names == list(mc.COLUMNS)
    table = data.to_table(columns=['landing_x', 'spin_rpm'])  # only the columns asked for
    assert np.array_equal(table['landing_x'].to_numpy(), reference.rows['landing_x'])
    assert np.array_equal(table['spin_rpm'].to_numpy(), reference.rows['spin_rpm'])
    # Exact statistics, a subsample of 100 rows per chunk for the quantiles.
    assert stats.in_zone == reference.stats.in_zone and stats.landed == reference.stats.landed
    assert np.allclose(stats.covariance(), reference.stats.covariance(), rtol=1e-12, atol=1e-12)
    sample = stats.sample()['landing_x']
    assert sample.size == 300
    assert np.array_equal(sample[:100], reference.rows['landing_x'][:100])


def test_command_parquet_and_until_halfwidth_on_a_scheduler(cluster, tmp_path):
    folder = tmp_path / 'mc.parquet'
    folder.mkdir()
    (folder / 'part-00000099.parquet').write_bytes(b'stale')  # an older run's partition
    args = ('--n', '300000', '--zone', *map(str, ZONE), '--until-halfwidth', '0.004')
    out = _cli(*args, '--scheduler', cluster, '--out', str(folder)).stdout
    ref = _cli(*args, '--out', str(tmp_path / 'ref.npz'), '--figure', 'none').stdout
    first = out.splitlines()[0]
    balls = int(first.split()[0])
    assert balls % eng.CHUNK == 0 and balls < 300_000 and ref.startswith(f'{balls} balls')
    assert len(list(folder.glob('part-*.parquet'))) == balls // eng.CHUNK
    import pyarrow.dataset as ds

    landed = ds.dataset(folder, format='parquet').to_table(columns=['landing_x', 'landing_y'])
    with np.load(tmp_path / 'ref.npz') as r:
        assert np.array_equal(landed['landing_x'].to_numpy(), r['landing_x'])
    line = next(x for x in out.splitlines() if x.startswith('P(landing within 3 m'))
    assert line in ref and 'stopped: Wilson 95 % half-width' in out
    assert (tmp_path / 'mc.png').stat().st_size > 20_000


def test_a_failing_task_ends_the_run_with_its_error(cluster, tmp_path):
    plan = eng.Plan(
        Release(), mc.as_spread(mc.SPREAD_DEFAULTS), 0, N, None, str(tmp_path / 'missing')
    )
    with eng.Engine(scheduler=cluster) as engine:
        with pytest.raises(OSError):
            eng.drain(engine, plan)


@pytest.mark.parametrize('delay', [0.0, 3.0])  # while the cluster starts; while it flies
def test_ctrl_c_closes_the_local_cluster_without_a_traceback(tmp_path, delay):
    import signal
    import time

    import psutil

    proc = subprocess.Popen(
        [sys.executable, '-m', 'football_ros.cli', 'montecarlo', '--n', '2000000',
         '--workers', '2', '--out', 'none', '--quiet'],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        env=dict(os.environ, PYTHONFAULTHANDLER='1'),  # SIGABRT prints every thread's stack
        # SIGINT's default action, as from a terminal: a suite started in the background of a
        # script (nohup, or & without job control) has SIGINT ignored, children inherit that,
        # and Python then leaves it ignored (the run flies on, as such a script asked).
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        deadline = time.monotonic() + 120
        kids = []
        while time.monotonic() < deadline and len(kids) < 2:  # the 2 workers are up
            kids = psutil.Process(proc.pid).children(recursive=True)
            time.sleep(0.5)
        time.sleep(delay)
        assert len(kids) >= 2, kids
        proc.send_signal(signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:  # where it hangs: the stacks, then fail
            proc.send_signal(signal.SIGABRT)
            _, err = proc.communicate(timeout=30)
            pytest.fail(f'no exit within 60 s of SIGINT; its stacks:\n{err[-6000:]}')
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130 and 'Traceback' not in err, err
    assert 'interrupted' in err

    def alive() -> list[int]:
        return [k.pid for k in kids if k.is_running() and k.status() != psutil.STATUS_ZOMBIE]

    deadline = time.monotonic() + 30.0  # the workers end after the parent: wait for it
    while alive() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not alive()
