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


"""Monte Carlo: seeding, input distributions, counts, zone, ellipses, sensitivity, options."""

import math
import os
import subprocess
import sys

from football_ros.physics import Release
from football_ros.physics.aero import AeroModel, resolve
from football_ros.physics.linear_theory import linear_modes
from football_ros.physics.release import LIMITS
from football_ros.tools import mc_engine as eng
from football_ros.tools import montecarlo as mc
from hypothesis import given, settings
from hypothesis import strategies as hs
import numpy as np
import pytest
from scipy.special import ndtr
from scipy.stats import chi2


ZONE = (66.0, 0.0, 3.0)


def _run_cli(*args, timeout=300, cwd=None):
    return subprocess.run(
        [sys.executable, '-m', 'football_ros.cli', 'montecarlo', *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env={**os.environ, 'PYTHONPATH': os.pathsep.join(sys.path)},
    )


def test_chunk_seed_is_the_seed_sequence_child():
    children = np.random.SeedSequence(7).spawn(5)
    for i, child in enumerate(children):
        mine = eng.chunk_seed(7, i)
        assert np.array_equal(mine.generate_state(8), child.generate_state(8))


def test_samples_depend_on_the_ball_index_only():
    """The first balls of a run are a shorter run's; a partial last chunk is a prefix."""
    spread = mc.as_spread(mc.SPREAD_DEFAULTS)
    long = mc.sample_releases(Release(), spread, 25_000, seed=3)
    short = mc.sample_releases(Release(), spread, 12_345, seed=3)
    for key in eng.INPUT_KEYS:
        assert np.array_equal(long[key][:12_345], short[key])
    other = mc.sample_releases(Release(), spread, 100, seed=4)
    assert not np.array_equal(other['speed'], long['speed'][:100])
    # One input's error does not move another's draws.
    wider = dict(spread, spin_rpm=eng.Spread('normal', 90.0))
    again = mc.sample_releases(Release(), wider, 100, seed=3)
    assert np.array_equal(again['speed'], long['speed'][:100])
    assert np.allclose(again['spin_rpm'] - 600.0, 3 * (long['spin_rpm'][:100] - 600.0))


def test_distributions():
    release = Release(speed=20.0, spin_rpm=-700.0)
    spread = mc.parse_spread(
        ['speed=lognormal:0.1,spin_rpm=uniform:100', 'elevation_deg=normal:2,azimuth_deg=0']
    )
    s = mc.sample_releases(release, spread, 200_000, seed=1)
    log = np.log(s['speed'] / 20.0)
    assert np.median(s['speed']) == pytest.approx(20.0, rel=2e-3)
    assert log.mean() == pytest.approx(0.0, abs=1e-3) and log.std() == pytest.approx(0.1, 5e-3)
    assert s['spin_rpm'].min() >= -800.0 and s['spin_rpm'].max() <= -600.0
    assert s['spin_rpm'].std() == pytest.approx(200 / math.sqrt(12), rel=5e-3)  # uniform
    counts, _ = np.histogram(s['spin_rpm'], bins=10, range=(-800, -600))
    assert counts.min() > 0.95 * 20_000 and counts.max() < 1.05 * 20_000
    assert s['elevation_deg'].std() == pytest.approx(2.0, rel=5e-3)
    assert np.all(s['azimuth_deg'] == 0.0)
    # A log-normal error of a nominal 0 is refused.
    with pytest.raises(ValueError, match='alpha0_deg'):
        mc.check_spread(Release(), mc.parse_spread(['alpha0_deg=lognormal:0.1']))


@pytest.mark.parametrize(
    'item, match',
    [
        ('speed=-1', '>= 0'),
        ('mass=1', 'KEY one of'),
        ('speed=gamma:1', 'distribution'),
        ('speed=uniform:x', 'not a number'),
        ('speed=nan', 'finite'),
    ],
)
def test_parse_spread_refuses(item, match):
    with pytest.raises(ValueError, match=match):
        mc.parse_spread([item])


def test_clipped_samples_are_counted():
    """Issue 21: speed=100 clips about 77 % of the speeds into [1, 60], and says so."""
    spread = mc.parse_spread(['speed=100'])
    _, clipped = eng.sample_chunk(Release(), spread, 0, 0, 10_000)
    expected = ndtr((1.0 - 27.4) / 100.0) + 1.0 - ndtr((60.0 - 27.4) / 100.0)
    j = eng.INPUT_KEYS.index('speed')
    assert clipped[:, j].mean() == pytest.approx(expected, abs=0.015)
    assert expected == pytest.approx(0.768, abs=0.002)
    assert not clipped[:, [i for i in range(len(eng.INPUT_KEYS)) if i != j]].any()


def test_stable_flag_is_the_linear_theory_at_release():
    release = Release(model='full', aero={'air_density': 1.3, 'wind': [3.0, -2.0, 0.0]})
    spread = mc.parse_spread(['spin_rpm=150,speed=3'])
    samples, _ = eng.sample_chunk(release, spread, 5, 0, 64)
    out = eng.fly(release, samples)
    ball, aero = resolve(release.preset(), 'full', release.aero_model())
    expect = []
    for i in range(64):
        r = Release(
            model='full',
            aero={'air_density': 1.3, 'wind': [3.0, -2.0, 0.0]},
            **{k: float(samples[k][i]) for k in eng.INPUT_KEYS},
        )
        expect.append(linear_modes(ball, r.initial_state(), wind=np.array(aero.wind)).stable)
    assert 5 < sum(expect) < 59  # both sides of the critical spin
    assert np.array_equal(out['stable'].astype(bool), np.array(expect))


def test_stats_merge_equals_the_whole():
    rng = np.random.default_rng(0)
    n = 3000
    rows = {k: rng.normal(size=n) for k in eng.MOMENT_KEYS}
    rows.update(
        landed=(rng.random(n) > 0.1).astype(np.int8),
        stable=np.ones(n, np.int8),
        clipped=np.zeros(n, np.int8),
        max_alpha_deg=np.zeros(n),
        max_beta_deg=np.zeros(n),
        max_delta_deg=np.zeros(n),
        _clipped_by_key=np.zeros(len(eng.INPUT_KEYS), int),
    )
    whole = eng.Stats.of(rows, (0.0, 0.0, 1.0), n)
    merged = eng.Stats()
    for a, b in ((0, 1000), (1000, 1001), (1001, n)):
        part = {k: (v[a:b] if k != '_clipped_by_key' else v) for k, v in rows.items()}
        merged.merge(eng.Stats.of(part, (0.0, 0.0, 1.0), n))
    landed = rows['landed'].astype(bool)
    values = np.column_stack([rows[k][landed] for k in eng.MOMENT_KEYS])
    assert merged.count == whole.count == landed.sum()
    assert np.allclose(merged.mean, values.mean(axis=0), atol=1e-12)
    assert np.allclose(merged.covariance(), np.cov(values.T, bias=True), atol=1e-12)
    inside = landed & (rows['landing_x'] ** 2 + rows['landing_y'] ** 2 <= 1.0)
    assert merged.in_zone == whole.in_zone == inside.sum()
    assert np.array_equal(merged.sample()['landing_x'], rows['landing_x'])


def test_wilson_interval():
    assert eng.wilson(5, 10) == pytest.approx((0.5, 0.236593, 0.763407), abs=1e-6)
    p, lo, hi = eng.wilson(0, 100)
    assert p == 0.0 and lo == pytest.approx(0.0, abs=1e-15)
    assert hi == pytest.approx(0.036994, abs=1e-6)
    p, lo, hi = eng.wilson(9990, 10000)
    assert lo < p < hi < 1.0 and hi - lo == pytest.approx(0.00126, abs=5e-5)


def test_ellipse_holds_its_level():
    rng = np.random.default_rng(1)
    cov = np.array([[4.0, 1.5], [1.5, 1.0]])
    pts = rng.multivariate_normal([60.0, -3.0], cov, size=200_000)
    for level in (0.5, 0.95):
        major, minor, angle = eng.ellipse(cov, level)
        values = np.linalg.eigvalsh(cov)
        assert major * minor == pytest.approx(chi2.ppf(level, 2) * math.sqrt(np.prod(values)))
        inside = eng.inside_ellipse(pts[:, 0], pts[:, 1], (60.0, -3.0), cov, level).mean()
        assert inside == pytest.approx(level, abs=0.004)
    assert math.degrees(angle) == pytest.approx(
        math.degrees(0.5 * math.atan2(2 * 1.5, 4.0 - 1.0)), abs=1e-9
    )


def test_zone_sensitivity_and_ellipses_against_the_vacuum_range():
    """Paper model: the centre flies the vacuum parabola, so the slopes are known exactly."""
    spread = mc.parse_spread(
        ['alpha0_deg=0,beta0_deg=0,alpha_rate_deg_s=0,beta_rate_deg_s=0,spin_rpm=0']
    )
    out = mc.run(Release(), 20_000, spread, 2, progress=False, zone=(66.0, 0.0, 2.0))
    rows = out.rows
    v, th, az = rows['speed'], np.radians(rows['elevation_deg']), np.radians(rows['azimuth_deg'])
    rng = v**2 * np.sin(2 * th) / 9.81
    assert np.allclose(rows['landing_x'], rng * np.cos(az), atol=1e-5)
    sens = {k: (b, s) for k, b, s in eng.sensitivity(out.stats, 'landing_x')}
    v0, th0 = 27.4, math.radians(30.0)
    assert sens['speed'][0] == pytest.approx(2 * v0 * math.sin(2 * th0) / 9.81, rel=0.01)
    assert sens['elevation_deg'][0] == pytest.approx(
        2 * v0**2 * math.cos(2 * th0) / 9.81 * math.pi / 180, rel=0.02
    )
    share = (4.838**2 * 0.25) / (4.838**2 * 0.25 + 1.3357**2)
    assert sens['speed'][1] == pytest.approx(share, abs=0.02)
    assert eng.fit_r2(out.stats, 'landing_x') > 0.999  # the vacuum range is nearly linear
    assert sum(s for _, s in sens.values()) == pytest.approx(1.0, abs=0.02)
    sy = {k: s for k, _, s in eng.sensitivity(out.stats, 'landing_y')}
    assert sy['azimuth_deg'] > 0.99
    d2 = (rows['landing_x'] - 66.0) ** 2 + rows['landing_y'] ** 2
    assert out.stats.in_zone == np.count_nonzero(d2 <= 4.0)
    lines = '\n'.join(mc.summary(out, Release(), spread))
    p, lo, hi = eng.wilson(out.stats.in_zone, 20_000)
    assert f'= {p:.4f}, Wilson 95 %: [{lo:.4f}, {hi:.4f}]' in lines
    (l50, cx, cy, a50, b50, _), (l95, *_, a95, b95, _) = mc.ellipses(out.stats)
    assert (cx, cy) == pytest.approx((rows['landing_x'].mean(), rows['landing_y'].mean()))
    assert a95 / a50 == pytest.approx(math.sqrt(chi2.ppf(0.95, 2) / chi2.ppf(0.5, 2)))
    assert ' 50 %' in lines and ' 95 %' in lines and 'share x' in lines


def test_until_halfwidth_stops_at_the_first_narrow_chunk():
    zone = (66.0, 0.0, 3.0)
    out = mc.run(
        Release(), 200_000, mc.SPREAD_DEFAULTS, 0, False, zone=zone, until_halfwidth=0.005
    )
    assert out.n % eng.CHUNK == 0 and eng.CHUNK < out.n < 200_000
    rows = out.rows
    inside = (rows['landing_x'] - 66.0) ** 2 + rows['landing_y'] ** 2 <= 9.0
    _, lo, hi = eng.wilson(int(inside.sum()), out.n)
    assert (hi - lo) / 2 <= 0.005
    prev = out.n - eng.CHUNK
    _, lo, hi = eng.wilson(int(inside[:prev].sum()), prev)
    assert (hi - lo) / 2 > 0.005
    assert 'Wilson 95 % half-width' in out.stopped


def test_aero_refuses_conflicting_air_settings():
    for extra in ({'altitude_m': 6000.0}, {'temperature_c': 30.0}):
        with pytest.raises(ValueError, match="'air_density' conflicts"):
            AeroModel(air_density=1.0, **extra)
    assert AeroModel(altitude_m=6000.0, temperature_c=-20.0).density(1.225) < 0.75
    proc = _run_cli(
        '--model', 'full', '--aero', 'altitude_m=6000', '--aero', 'air_density=1.0',
        '--out', '/tmp/never.csv', timeout=120,
    )
    assert proc.returncode == 2 and 'conflicts' in proc.stderr


def test_clipped_and_unstable_balls_are_reported(tmp_path):
    out = tmp_path / 'mc.npz'
    proc = _run_cli(
        '--n', '3000', '--spread', 'speed=100', '--spin-rpm', '450', '--quiet',
        '--figure', 'none', '--out', str(out),
    )
    assert proc.returncode == 0, proc.stderr
    with np.load(out) as data:
        clipped = int(data['clipped'].sum())
        unstable = int((data['stable'] == 0).sum())
        speed = data['speed']
        assert np.all((speed >= LIMITS['speed'][0]) & (speed <= LIMITS['speed'][1]))
        # Below the critical spin's speed: 450 rpm holds the axis up to some speed only.
        assert np.array_equal(data['clipped'] == 1, (speed == 1.0) | (speed == 60.0))
    assert 0.74 < clipped / 3000 < 0.80 and 0 < unstable < 3000
    assert f'speed samples ({clipped} of 3000) fell outside [1, 60] m/s' in proc.stderr
    assert f'{unstable} of 3000 balls' in proc.stderr and 'critical spin' in proc.stderr
    assert f'clipped into the accepted ranges: {clipped} balls' in proc.stdout
    assert f'(spin below the critical spin): {unstable} balls' in proc.stdout


@pytest.mark.parametrize(
    'args, match',
    [
        (['--zone', '60', '0', '0'], '0 < R'),
        (['--zone', '60', '0', 'nan'], '0 < R'),
        (['--zone', '1e308', '1e308', '1e308'], 'X and Y in'),
        (['--zone', '60', 'inf', '2'], 'X and Y in'),
        (['--until-halfwidth', '0.01'], 'needs --zone'),
        (['--zone', '60', '0', '2', '--until-halfwidth', '0'], '(0, 0.5]'),
        (['--workers', '0'], '--workers'),
        (['--workers', '2', '--scheduler', 'tcp://127.0.0.1:1'], 'exclude'),
        (['--seed', '-1'], '--seed'),
        (['--task-chunks', '0'], '--task-chunks'),
        (['--spread', 'beta0_deg=lognormal:0.2'], 'beta0_deg'),
        (['--n', '20000000'], 'DIR.parquet'),
        (['--out', '{tmp}/x.parquet/y.csv'], 'folder'),
        (['--out', '{tmp}/file.parquet'], 'not a folder'),
    ],
)
def test_bad_options_fail_before_any_work(tmp_path, args, match):
    (tmp_path / 'file.parquet').write_text('x')
    args = [a.replace('{tmp}', str(tmp_path)) for a in args]
    if '--out' not in args:
        args += ['--out', str(tmp_path / 'x.csv')]
    proc = _run_cli('--n', '2000000', *args, timeout=120) if '--n' not in args else _run_cli(
        *args, timeout=120
    )
    assert proc.returncode == 2 and proc.stderr.startswith('football-ros: error:'), proc.stderr
    assert match in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not list(tmp_path.glob('*.csv'))


def test_figure_labels_are_inside_the_png():
    """Issue 21: the density figure cut its y label; every label is inside the canvas."""
    rng = np.random.default_rng(0)
    n = 20_000
    data = {
        'landing_x': rng.normal(61, 2, n),
        'landing_y': rng.normal(-3, 1, n),
        'time_of_flight': rng.normal(2.8, 0.1, n),
        'landed': np.ones(n, np.int8),
        'max_alpha_deg': rng.normal(4, 1, n),
        'max_beta_deg': rng.normal(9, 1, n),
        'max_delta_deg': rng.normal(9, 1, n),
        'ellipses': [(0.5, 61, -3, 2.4, 1.2, 0.0), (0.95, 61, -3, 4.9, 2.4, 0.0)],
        'landed_total': n,
    }
    fig = mc.figure(data, 'test')
    fig.canvas.draw()
    box = fig.bbox
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        for label in (ax.yaxis.label, ax.xaxis.label, ax.title):
            if label.get_text():
                ext = label.get_window_extent(renderer)
                assert ext.x0 >= box.x0 and ext.x1 <= box.x1, label.get_text()
                assert ext.y0 >= box.y0 and ext.y1 <= box.y1, label.get_text()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_chunks_flown_from_several_threads_at_once_are_the_chunks_flown_one_by_one():
    """What a Dask worker with several task threads does: no hang, no crosstalk."""
    from concurrent.futures import ThreadPoolExecutor

    plan = eng.Plan(Release(), mc.as_spread(mc.SPREAD_DEFAULTS), 9, 8 * 1500, chunk=1500)
    alone = [eng.run_task(plan, i, i + 1, threads=1)[0] for i in range(8)]
    with ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(eng.run_task, plan, i, i + 1, 1) for i in range(8)]
        together = [f.result(timeout=120)[0] for f in futures]
    for a, b in zip(alone, together):
        assert a.index == b.index and b.threads == 1
        for key in mc.COLUMNS:
            assert np.array_equal(a.rows[key], b.rows[key]), key
    # The guard: a lock unless numba's threading layer is thread-safe.
    import numba

    assert eng._THREAD_SAFE == (numba.threading_layer() in ('omp', 'tbb'))
    saved = eng._THREAD_SAFE
    try:
        eng._THREAD_SAFE = False
        assert eng._kernel_guard() is eng._KERNEL_LOCK
    finally:
        eng._THREAD_SAFE = saved
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)  # this thread's, as before


def test_progress_bar_shows_rate_and_time_left(tmp_path):
    proc = _run_cli('--n', '30000', '--figure', 'none', '--out', str(tmp_path / 'mc.npz'))
    assert proc.returncode == 0, proc.stderr
    last = proc.stderr.replace('\r', '\n').strip().splitlines()[-1]
    assert '30.0k/30.0k' in last and 'ball/s' in last and '<00:00' in last, last


def test_statistics_only_runs_keep_no_rows(tmp_path):
    full = mc.run(Release(), 12_000, mc.SPREAD_DEFAULTS, 4, False, zone=ZONE)
    lean = mc.run(Release(), 12_000, mc.SPREAD_DEFAULTS, 4, False, zone=ZONE, gather=False)
    assert lean.rows is None and full.rows['landing_x'].size == 12_000
    assert lean.stats.in_zone == full.stats.in_zone
    assert np.array_equal(lean.stats.m2, full.stats.m2)
    proc = _run_cli('--n', '12000', '--seed', '4', '--quiet', '--out', 'none', cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert 'per-ball results: none' in proc.stdout and not list(tmp_path.iterdir())
    table = '\n'.join(mc.summary(full, Release(), mc.parse_spread([])))
    assert proc.stdout.splitlines()[2] in table  # the same landing x statistics


def test_progress_without_tqdm_is_a_plain_bar(capsys):
    bar = mc._Bar(total=30_000, file=sys.stderr, mininterval=0.0)
    for _ in range(3):
        bar.update(10_000)
    bar.close()
    last = capsys.readouterr().err.replace('\r', '\n').strip().splitlines()[-1]
    assert '30000/30000 balls' in last and 'ball/s' in last and '<0 s left' in last


@settings(max_examples=300, deadline=None)
@given(hs.lists(hs.text(max_size=40), max_size=4))
def test_parse_spread_takes_any_text_without_crashing(items):
    """Any --spread text: a clear ValueError, or finite widths >= 0 of a known distribution."""
    try:
        spread = mc.parse_spread(items)
    except ValueError as exc:
        assert str(exc).startswith('--spread')
        return
    assert set(spread) == set(eng.INPUT_KEYS)
    for s in spread.values():
        assert s.dist in eng.DISTRIBUTIONS and math.isfinite(s.width) and s.width >= 0


@settings(max_examples=300, deadline=None)
@given(
    hs.tuples(*[hs.floats(allow_nan=True, allow_infinity=True)] * 3),
    hs.one_of(hs.none(), hs.floats(allow_nan=True, allow_infinity=True)),
)
def test_zone_options_are_checked(zone, halfwidth):
    try:
        checked = mc.check_zone(zone, halfwidth)
    except ValueError as exc:
        assert str(exc).startswith(('--zone', '--until-halfwidth'))
        return
    x, y, r = checked
    assert abs(x) <= 1e4 and abs(y) <= 1e4 and 0 < r <= 2e4
    assert halfwidth is None or 0 < halfwidth <= 0.5
    # The zone test stays finite: a ball at the far corner is outside, not inf <= inf.
    rows = {k: np.zeros(1) for k in (*eng.MOMENT_KEYS, *eng.SUMMARY_KEYS)}
    rows.update(
        landing_x=np.array([-1e4]), landing_y=np.array([-1e4]), landed=np.ones(1, np.int8),
        stable=np.ones(1, np.int8), clipped=np.zeros(1, np.int8),
        _clipped_by_key=np.zeros(len(eng.INPUT_KEYS), int),
    )
    inside = eng.Stats.of(rows, checked, 1).in_zone
    assert inside == int((-1e4 - x) ** 2 + (-1e4 - y) ** 2 <= r * r)
