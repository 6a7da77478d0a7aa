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
``football-ros fit`` and football_ros.identification against flights of known coefficients.

The truth comes from the package's simulator (``Flight``, RK4 at 1 ms) with coefficients other
than the fit's defaults; the fit starts from the defaults and is told only what it does not
free. Checks: recovery within the reported intervals, coverage over a few trials (a bound a
mis-scaled interval fails), identifiability verdicts (never a number), the CLI's JSON and its
round trip into ``simulate``, and hostile files (named by file and line), fuzzed.
"""

from __future__ import annotations

from dataclasses import replace
import json
import math
from pathlib import Path

from cli_run import run_cli
from football_ros.identification import fit, FitSettings, Track
from football_ros.physics import Flight, get_preset, Release
from football_ros.physics.aero import AeroModel
from football_ros.tools.tracks import read_csv, read_tracks
from hypothesis import given, HealthCheck, settings, strategies as st
import numpy as np
import pytest

TRUTH_AERO = {'c_d0': 0.075, 'c_l_alpha': 0.30}
TRUTH_BALL = {'c_m_alpha': 0.28}


def flight(rng, speed=25.0, elevation=28.0, noise=0.02, axis_noise=None, aero=TRUTH_AERO,
           ball=TRUTH_BALL, duration=10.0, wobble=0.0):
    """
    Return (t, positions, axes) of a pass of the truth, with noise; axes None unless asked.

    The axis starts off the velocity by N(0, 2 deg) per angle, turning at N(0, ``wobble``)
    [deg/s] per angle.
    """
    rates = rng.normal(0.0, wobble, 2) if wobble else (0.0, 0.0)
    release = Release(ball='american', speed=speed, elevation_deg=elevation,
                      azimuth_deg=rng.uniform(-10.0, 10.0), spin_rpm=600.0,
                      alpha0_deg=rng.normal(0.0, 2.0), beta0_deg=rng.normal(0.0, 2.0),
                      alpha_rate_deg_s=rates[0], beta_rate_deg_s=rates[1],
                      position=(0.0, 0.0, 1.8), model='full', aero=aero, ball_params=ball)
    trajectory = Flight.from_release(release).simulate(rate=100.0, duration=duration)
    n = trajectory.times.size - 1 if trajectory.landed else trajectory.times.size
    pos = trajectory.positions[:n] + rng.normal(0.0, noise, (n, 3))
    axes = None
    if axis_noise is not None:
        axes = trajectory.axes[:n] + rng.normal(0.0, axis_noise, (n, 3))
        axes /= np.linalg.norm(axes, axis=1)[:, None]
    return trajectory.times[:n] + 3.0, pos, axes  # any clock


def told(free, ball=TRUTH_BALL, aero=TRUTH_AERO):
    """Return settings telling the truth's values of what is not freed (defaults otherwise)."""
    return FitSettings(get_preset('american', {k: v for k, v in ball.items() if k not in free}),
                       free=free,
                       aero=AeroModel.from_mapping({k: v for k, v in aero.items()
                                                    if k not in free}))


def test_recovers_drag_lift_and_moment_from_positions_and_axes():
    rng = np.random.default_rng(3)
    tracks = []
    for speed, elevation in ((24.0, 25.0), (27.0, 32.0)):
        t, pos, axes = flight(rng, speed, elevation, axis_noise=math.radians(1.0))
        tracks.append(Track(t, pos, axes=axes))
    free = ('c_d0', 'c_l_alpha', 'c_m_alpha')
    result = fit(tracks, told(free))
    truth = {'c_d0': 0.075, 'c_l_alpha': 0.30, 'c_m_alpha': 0.28}
    for name, value in truth.items():
        c = result.coefficients[name]
        assert c.identifiable, (name, c.reason)
        assert abs(c.value - value) <= 3.0 * c.sigma, (name, c.value, c.sigma)
        assert abs(c.value - value) <= 0.05 * value, (name, c.value)
        assert c.ci95[1] - c.ci95[0] < 0.2 * value  # informative, not merely wide
    # The noise estimates find the truth's 2 cm and 1 deg.
    assert result.noise_m == pytest.approx(0.02, rel=0.1)
    assert result.axis_noise_deg == pytest.approx(1.0, rel=0.1)
    assert result.residual_rms_m == pytest.approx(0.02, rel=0.1)
    # Each flight's release state is the truth's: it started at 1.8 m, 3 s on the track's clock.
    for f in result.flights:
        assert f.t0 == pytest.approx(3.0)
        assert f.position[2] == pytest.approx(1.8, abs=0.03)
        assert f.spin_rpm == 600.0


def test_coverage_of_the_intervals_over_trials():
    """
    20 one-pass trials (positions): each identifiable interval holds the truth in at least 15.

    At the nominal 95 % the chance of 14 or fewer is 0.3 %; intervals half as wide as they
    should be cover about 68 %, and fail this 82 % of the time.
    """
    rng = np.random.default_rng(11)
    free = ('c_d0', 'c_l_alpha')
    hits = {name: [0, 0] for name in free}
    for _ in range(20):
        result = fit([Track(*flight(rng, speed=rng.uniform(22, 27),
                                    elevation=rng.uniform(20, 32))[:2])], told(free))
        for name in free:
            c = result.coefficients[name]
            if c.identifiable:
                hits[name][1] += 1
                hits[name][0] += int(c.ci95[0] <= TRUTH_AERO[name] <= c.ci95[1])
    for name, (k, n) in hits.items():
        assert n >= 18, (name, n)  # a 2.5 s pass determines both
        assert k >= n - 5, (name, k, n)


def _passes(seed, wobble, n=8):
    rng = np.random.default_rng(seed)
    return [Track(*flight(rng, speed=rng.uniform(22, 27), elevation=rng.uniform(20, 32),
                          wobble=wobble)[:2]) for _ in range(n)]


def test_steady_passes_hold_their_release_rate_and_keep_the_drag_unbiased():
    """
    Positions of passes released without a wobble rate: 'auto' holds the rate at zero.

    Freed, each pass's rate fits the noise and only adds mean drag (C_D2 sin^2 delta), so C_D0
    falls: below the held fit's value, the one-sided bias many passes do not average out.
    """
    tracks = _passes(1, 0.0)
    settings = replace(told(('c_d0', 'c_l_alpha')), profile=False)
    held = fit(tracks, settings)
    assert not any(f.rate_fitted for f in held.flights)
    assert all(np.linalg.norm(f.transverse_rate) < 1e-4 for f in held.flights)
    d0 = held.coefficients['c_d0']
    assert abs(d0.value - 0.075) <= 2.5 * d0.sigma, (d0.value, d0.sigma)
    freed = fit(tracks, replace(settings, release_rate='free'))
    assert all(f.rate_fitted for f in freed.flights)
    assert freed.coefficients['c_d0'].value < d0.value - d0.sigma


def test_wobbling_passes_free_their_release_rate():
    """
    Passes released turning at N(0, 150 deg/s) per angle: the positions show the wobble.

    'auto' frees every rate and C_D0 holds the truth; held at zero, the wobble's mean drag
    goes into C_D0, far beyond its interval.
    """
    tracks = _passes(1, 150.0)
    settings = replace(told(('c_d0', 'c_l_alpha')), profile=False)
    auto = fit(tracks, settings)
    assert all(f.rate_fitted for f in auto.flights)
    d0 = auto.coefficients['c_d0']
    assert abs(d0.value - 0.075) <= 2.5 * d0.sigma, (d0.value, d0.sigma)
    held = fit(tracks, replace(settings, release_rate='held')).coefficients['c_d0']
    assert held.value - 0.075 > 5.0 * held.sigma


def test_magnus_from_a_short_pass_is_not_identifiable_and_has_no_number():
    rng = np.random.default_rng(5)
    t, pos, _ = flight(rng, speed=13.0, elevation=5.0)
    assert t[-1] - t[0] < 0.9  # a short pass
    result = fit([Track(t, pos)], told(('c_d0', 'c_l_alpha', 'c_n_p_alpha')))
    magnus = result.coefficients['c_n_p_alpha']
    assert not magnus.identifiable
    assert magnus.value is None and magnus.ci95 is None and magnus.interval is None
    assert 'physical range' in magnus.reason or 'near-null' in magnus.reason
    assert np.isnan(result.correlation[2]).all()


def test_paper_model_positions_say_nothing_of_the_moment():
    """The paper's model has no air force: positions alone cannot tell C_Malpha."""
    rng = np.random.default_rng(2)
    release = Release(ball='rugby', speed=20.0, elevation_deg=30.0, position=(0, 0, 1.5))
    trajectory = Flight.from_release(release).simulate(rate=100.0)
    n = trajectory.times.size - 1
    track = Track(trajectory.times[:n], trajectory.positions[:n] + rng.normal(0, 0.01, (n, 3)))
    result = fit([track], FitSettings(get_preset('rugby'), model='paper'))
    c = result.coefficients['c_m_alpha']
    assert not c.identifiable and c.value is None and c.ci95 is None
    assert result.residual_rms_m == pytest.approx(0.01, rel=0.15)  # a parabola fits


def test_paper_model_moment_from_observed_axes():
    rng = np.random.default_rng(4)
    release = Release(ball='rugby', speed=20.0, elevation_deg=30.0, position=(0, 0, 1.5),
                      alpha0_deg=4.0, ball_params={'c_m_alpha': 0.12})
    trajectory = Flight.from_release(release).simulate(rate=100.0)
    n = trajectory.times.size - 1
    axes = trajectory.axes[:n] + rng.normal(0, math.radians(1.0), (n, 3))
    track = Track(trajectory.times[:n], trajectory.positions[:n] + rng.normal(0, 0.01, (n, 3)),
                  axes=-axes)  # the axis seen end for end: the fit takes either sign
    result = fit([track], FitSettings(get_preset('rugby'), model='paper'))
    c = result.coefficients['c_m_alpha']
    assert c.identifiable and abs(c.value - 0.12) <= 3.0 * c.sigma  # 1 deg gives 0.2 %
    assert c.value == pytest.approx(0.12, rel=0.02)


def _write_csv(path: Path, t, pos, sigma=None) -> Path:
    cols = [t, pos[:, 0], pos[:, 1], pos[:, 2]] + ([sigma] if sigma is not None else [])
    header = 't,x,y,z' + (',sigma' if sigma is not None else '')
    np.savetxt(path, np.column_stack(cols), delimiter=',', header=header, comments='')
    return path


def test_cli_json_shape_and_its_coefficients_fly_in_simulate(tmp_path):
    rng = np.random.default_rng(8)
    paths = [_write_csv(tmp_path / f'pass{i}.csv', *flight(rng, speed=24.0 + 2 * i)[:2])
             for i in range(2)]
    out = run_cli('fit', *map(str, paths), '--ball', 'american', '--free',
                  'c_d0,c_l_alpha,c_n_p_alpha', '--ball-param', 'c_m_alpha=0.28', '--json',
                  '--out', str(tmp_path / 'figs'))
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert set(report) >= {'coefficients', 'residual_rms_m', 'flights', 'simulate_args'}
    assert list(report['coefficients']) == ['c_d0', 'c_l_alpha', 'c_n_p_alpha']
    for name, c in report['coefficients'].items():
        assert set(c) >= {'value', 'ci95', 'identifiable'}
        if c['identifiable']:
            lo, hi = c['ci95']
            assert lo <= c['value'] <= hi
        else:
            assert c['value'] is None and c['ci95'] is None and c['reason']
    d0 = report['coefficients']['c_d0']
    assert d0['identifiable'] and d0['ci95'][0] <= 0.075 <= d0['ci95'][1]
    assert report['residual_rms_m'] == pytest.approx(0.02, rel=0.15)
    assert [f['source'] for f in report['flights']] == [str(p) for p in paths]
    assert (tmp_path / 'figs' / 'residuals.png').stat().st_size > 0
    assert json.loads((tmp_path / 'figs' / 'fit.json').read_text()) == report
    # simulate takes the fitted model as it is printed.
    from football_ros.cli import build_parser
    from football_ros.command_line import release_from_args

    args = build_parser().parse_args(['simulate', *report['simulate_args'], '--out', 'x.csv'])
    release = release_from_args(args)
    assert release.model == 'full' and release.ball_params == {'c_m_alpha': 0.28}
    assert release.aero['c_d0'] == pytest.approx(d0['value'], rel=1e-5)
    if not report['coefficients']['c_n_p_alpha']['identifiable']:
        assert 'c_n_p_alpha' not in release.aero
    text = run_cli('fit', str(paths[0]), '--ball', 'american', '--no-profile')
    assert text.returncode == 0, text.stderr
    assert 'c_d0' in text.stdout and 'simulate with: football-ros simulate' in text.stdout


def test_a_flight_of_another_model_is_warned_of_not_given_a_bare_number(tmp_path):
    """
    A flight of another model is flagged: a vacuum parabola under 9.75 m/s^2.

    The full model (g 9.81) matches it only with a negative C_D0; the report says the model
    does not fit rather than giving only a number.
    """
    t = np.arange(0.0, 2.5, 0.01)
    pos = np.column_stack([20.0 * t, 0.0 * t, 1.8 + 10.0 * t - 0.5 * 9.75 * t**2])
    pos += np.random.default_rng(6).normal(0.0, 0.005, pos.shape)
    path = _write_csv(tmp_path / 'moon.csv', t, pos)
    out = run_cli('fit', str(path), '--ball', 'american', '--no-profile', '--json')
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    d0 = report['coefficients']['c_d0']
    assert d0['identifiable'] and d0['ci95'][1] < 0.0
    assert any('c_d0: its 95 % interval is outside its physical range' in w
               for w in report['warnings'])


def test_reads_a_bag_of_observations_split_into_flights(tmp_path):
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import get_typestore, Stores

    typestore = get_typestore(Stores.ROS2_JAZZY)
    types = typestore.types
    rng = np.random.default_rng(6)
    flights = [flight(rng, speed=s)[:2] for s in (24.0, 26.0)]
    with Writer(tmp_path / 'bag', version=9) as writer:
        conn = writer.add_connection('/football/observation', 'geometry_msgs/msg/PointStamped',
                                     typestore=typestore)
        for k, (t, pos) in enumerate(flights):
            for ti, p in zip(t + 20.0 * k, pos):
                sec = int(ti)
                msg = types['geometry_msgs/msg/PointStamped'](
                    types['std_msgs/msg/Header'](
                        types['builtin_interfaces/msg/Time'](sec, int((ti - sec) * 1e9)),
                        'field'),
                    types['geometry_msgs/msg/Point'](*map(float, p)))
                writer.write(conn, int(ti * 1e9),
                             typestore.serialize_cdr(msg, 'geometry_msgs/msg/PointStamped'))
    tracks, warnings = read_tracks(tmp_path / 'bag')
    assert warnings == [] and len(tracks) == 2
    for track, (t, pos) in zip(tracks, flights):
        assert track.times.size == t.size
        np.testing.assert_allclose(track.positions, pos)
    with pytest.raises(ValueError, match='no PointStamped or PoseStamped topic'):
        read_tracks(tmp_path / 'bag', topic='/elsewhere')


HOSTILE = [
    ('t,x,y\n0,0,0\n', 'line 1: the header lacks column'),
    ('t,x,y,z\n' + ''.join(f'{i * 0.01},{i},0,1\n' for i in range(5)), '5 fix(es)'),
    ('t,x,y,z\n' + ''.join(f'{(i if i != 6 else 3) * 0.01},{i},0,1\n' for i in range(20)),
     'line 8: time 0.03 s is not after'),
    ('t,x,y,z\n' + ''.join(f'{i * 0.01},{"nan" if i == 9 else i},0,1\n' for i in range(20)),
     "line 11: column 'x' is not finite"),
    ('t,x,y,z\n' + ''.join(f'{i * 0.01},{i},0,1\n' for i in range(9)) + '0.1,abc,0,1\n'
     + ''.join(f'{i * 0.01},{i},0,1\n' for i in range(11, 20)), "line 11: column 'x' is not"),
    ('t,x,y,z\n' + ''.join(f'{i * 0.001},{i},0,1\n' for i in range(20)), 'span 0.019 s'),
    ('t,x,y,z\n' + ''.join(f'{i * 0.01},{i},0\n' for i in range(20)), 'line 2: 3 cells'),
    ('t,x,y,z,sigma\n' + ''.join(f'{i * 0.01},{i},0,1,{-1 if i == 4 else 0.01}\n'
                                 for i in range(20)), 'line 6: sigma must be'),
    ('t,x,y,z,sx,sy,sz\n' + ''.join(f'{i * 0.01},{i},0,1,1,0,{"" if i == 2 else 0}\n'
                                    for i in range(20)), 'line 4: spin axis must be three'),
    ('t,x,y,z\n' + ''.join(f'{i * 0.01},{i},0,1\n' for i in range(19)) + '100,0,0,1\n',
     'line 21: t = 100 s is more than 30 s'),
]


@pytest.mark.parametrize('text, message', HOSTILE)
def test_hostile_csv_is_refused_naming_file_and_line(tmp_path, text, message):
    path = tmp_path / 'track.csv'
    path.write_text(text)
    with pytest.raises(ValueError, match=message.replace('(', r'\(').replace(')', r'\)')) as err:
        read_csv(path)
    assert str(path) in str(err.value)


def test_hostile_csv_through_the_command_is_one_line_and_exit_2(tmp_path):
    path = tmp_path / 'bad.csv'
    path.write_text(HOSTILE[2][0])
    out = run_cli('fit', str(path), '--ball', 'rugby')
    assert out.returncode == 2
    assert out.stderr.strip().count('\n') == 0 and f'{path} line 8' in out.stderr
    for args, message in ((['--free', 'c_x'], "unknown coefficient 'c_x'"),
                          (['--model', 'paper', '--free', 'c_d0'], 'does not act in the paper'),
                          (['--noise', '-1'], '--noise must be'),
                          (['--aero', 'lift=false', '--free', 'c_l_alpha'], 'switched off')):
        out = run_cli('fit', str(path), '--ball', 'american', *args)
        assert out.returncode == 2 and message in out.stderr, (args, out.stderr)


CELL = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                 st.integers(-10**30, 10**30).map(str), st.text(max_size=6),
                 st.sampled_from(['', ' ', '1e999', '-0', 'nan', '0x10', '1_0']))


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(header=st.lists(st.sampled_from(['t', 'x', 'y', 'z', 'sx', 'sy', 'sz', 'sigma', 'q', '']),
                       min_size=0, max_size=9),
       rows=st.lists(st.lists(CELL, min_size=0, max_size=9), max_size=40),
       good=st.booleans())
def test_fuzzed_csv_gives_a_track_or_an_error_naming_the_file(tmp_path, header, rows, good):
    path = tmp_path / 'fuzz.csv'
    if good:  # a valid track with one fuzzed row somewhere
        header = ['t', 'x', 'y', 'z']
        base = [[f'{i * 0.02}', f'{i}', '0', '2'] for i in range(30)]
        if rows:
            base[len(rows) % 30] = rows[0][:4] + [''] * (4 - len(rows[0][:4]))
        rows = base
    path.write_text(','.join(header) + '\n' + ''.join(','.join(r) + '\n' for r in rows))
    try:
        track = read_csv(path)
    except ValueError as exc:
        assert str(path) in str(exc)
        return
    assert np.all(np.isfinite(track.positions)) and np.all(np.diff(track.times) > 0)


@settings(max_examples=60, deadline=None)
@given(data=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=0,
                     max_size=120))
def test_fuzzed_arrays_make_a_track_or_an_error(data):
    arr = np.array(data + [0.0] * (-len(data) % 4)).reshape(-1, 4)
    try:
        Track(arr[:, 0], arr[:, 1:4], name='fuzzed')
    except ValueError as exc:
        assert str(exc).startswith('fuzzed')
