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

"""Batch prediction and Monte Carlo: same physics as the single-flight kernel, real numbers."""

import csv
import math
import subprocess
import sys

from football_ros.physics import dynamics as dyn
from football_ros.physics import Flight, frames, get_preset, Release
from football_ros.physics.aero import AeroModel, resolve
from football_ros.physics.batch import fastest_rates, lean_states, simulate_batch
from football_ros.physics.dynamics import make_params
from football_ros.physics.release import LIMITS, release_states, ReleaseError, STATE_KEYS
from football_ros.tools.montecarlo import COLUMNS
from hypothesis import assume, given, HealthCheck, settings
from hypothesis import strategies as hs
import numpy as np
import pytest
from scipy.integrate import solve_ivp

RELEASES = [
    Release(),
    Release(spin_rpm=-700.0, alpha0_deg=3.0, beta_rate_deg_s=25.0),
    Release(ball='rugby'),
    Release(speed=18.0, elevation_deg=45.0, azimuth_deg=30.0, spin_rpm=450.0),
    Release(position=(1.0, -2.0, 2.0), elevation_deg=10.0, spin_rpm=900.0, alpha0_deg=-4.0),
]


def states_of(releases):
    cols = [np.array([getattr(r, k) for r in releases]) for k in STATE_KEYS]
    return release_states(*cols, np.array([r.position for r in releases]))


@pytest.mark.parametrize('model', ['paper', 'full'])
def test_batch_landings_match_single_flights(model):
    american = [r.replace(model=model) for r in RELEASES if r.ball == 'american']
    result = simulate_batch(get_preset('american'), states_of(american), model)
    for i, release in enumerate(american):
        tr = Flight.from_release(release).simulate(rate=100.0, duration=20.0)
        assert result.landed[i] and tr.landed
        assert result.time_of_flight[i] == pytest.approx(tr.times[-1], abs=1e-6)
        assert result.landing_x[i] == pytest.approx(tr.positions[-1, 0], abs=1e-5)
        assert result.landing_y[i] == pytest.approx(tr.positions[-1, 1], abs=1e-5)
        dense = Flight.from_release(release).simulate(rate=1000.0, duration=20.0)
        assert result.max_beta[i] == pytest.approx(
            np.max(np.abs(dense.aero_angles[:, 1])), abs=2e-3
        )
        assert result.max_beta[i] <= np.max(np.abs(dense.aero_angles[:, 1])) + 1e-6


def test_batch_angles_are_against_the_air_as_the_single_flight_s():
    """
    With wind the batch's largest alpha, beta, delta are the single flight's.

    The single flight's angles are taken against the air (v - wind).
    """
    from football_ros.physics.aero import AeroModel

    release = Release(model='full', aero={'wind': [-3.0, -6.0, 1.0]})
    result = simulate_batch(
        release.preset(), states_of([release]), 'full', aero=AeroModel.from_mapping(release.aero)
    )
    dense = Flight.from_release(release).simulate(rate=1000.0, duration=20.0)
    angles = np.abs(dense.aero_angles)  # against the ground they would be 0.04-0.08 rad larger
    assert result.max_alpha[0] == pytest.approx(angles[:, 0].max(), abs=5e-3)
    assert result.max_beta[0] == pytest.approx(angles[:, 1].max(), abs=5e-3)
    assert result.max_delta[0] == pytest.approx(angles[:, 2].max(), abs=5e-3)


def test_batch_angles_within_1e6_of_tight_dop853():
    ball = get_preset('american')
    st = states_of([RELEASES[1]])
    k = ball.moment_coefficient()

    def rhs(_t, y):
        v, s, h = y[3:6], y[6:9], y[9:12]
        return np.concatenate(
            [v, [0, 0, -9.81], np.cross(h, s), k * np.linalg.norm(v) * np.cross(v, s)]
        )

    probe = simulate_batch(ball, st, sample_count=1)
    times = np.arange(int(2.5 / probe.sample_period)) * probe.sample_period
    result = simulate_batch(ball, st, sample_period=probe.sample_period, sample_count=len(times))
    s0 = st['axis'][0]
    h0 = st['transverse_rate'][0] + ball.inertia_ratio * st['spin'][0] * s0
    sol = solve_ivp(
        rhs,
        (0, times[-1]),
        np.concatenate([st['position'][0], st['velocity'][0], s0, h0]),
        method='DOP853',
        rtol=1e-13,
        atol=1e-13,
        t_eval=times,
    )
    ref = frames.aero_angles(sol.y[6:9].T, sol.y[3:6].T)[:, :2]
    assert probe.sample_period > 0.02  # the 8th-order method takes long steps ...
    assert np.max(np.abs(result.samples[0] - ref)) < 1e-6  # ... at the accuracy asked for


def test_block_step_is_scipys_dop853_step_of_the_loads():
    """
    One step of the kernel's written-out stage sums = the DOP853 step computed here.

    The reference sums scipy's tableau (zeros included, positions included) in numpy on the
    lean equations of dynamics.loads (its Python source), then restores |s| = 1 and h.s = h1.
    """
    from football_ros.physics import batch as bt
    from scipy.integrate._ivp import dop853_coefficients as tableau

    ball, aero = resolve(get_preset('american'), 'full', AeroModel(wind=(2.0, -1.0, 0.5)))
    params = make_params(ball, 'sin2delta', aero)
    rng = np.random.default_rng(5)
    n, dt = 6, 0.03
    y = np.empty((n, 13))
    y[:, 0:3] = rng.normal(0.0, 5.0, (n, 3))
    y[:, 3:6] = [20.0, 0.0, 15.0] + rng.normal(0.0, 3.0, (n, 3))
    s = y[:, 3:6] + rng.normal(0.0, 4.0, (n, 3))
    y[:, 6:9] = s / np.linalg.norm(s, axis=1)[:, None]
    y[:, 9:12] = rng.normal(0.0, 30.0, (n, 3))
    y[:, 12] = np.sum(y[:, 9:12] * y[:, 6:9], axis=1)

    def rhs(x):
        a = dyn.loads.py_func(tuple(x[3:6]), tuple(x[6:9]), tuple(x[9:12]), x[12], params)
        return np.concatenate([x[3:6], a[:3], np.cross(x[9:12], x[6:9]), a[3:6], [a[6]]])

    stages = tableau.N_STAGES
    for b in range(n):
        k = np.zeros((stages, 13))
        for i in range(stages):
            k[i] = rhs(y[b] + dt * tableau.A[i, :stages] @ k)
        ref = y[b] + dt * tableau.B @ k
        ref[6:9] /= np.linalg.norm(ref[6:9])
        ref[9:12] += (ref[12] - ref[9:12] @ ref[6:9]) * ref[6:9]
        y_block = np.ascontiguousarray(y.T)
        out = np.empty_like(y_block)
        work = np.empty((stages, 13, n)), np.empty((13, n))
        bt._block_step(y_block, dt, params, work[0], work[1], out, n)
        scale = np.abs(ref) + np.abs(y[b]) + 1.0
        assert np.all(np.abs(out[:, b] - ref) <= 1e-13 * scale), (out[:, b] - ref) / scale
        assert np.abs(out[:, b] - y[b]).max() > 1e-3  # a real step


def test_results_come_back_in_input_order():
    rng = np.random.default_rng(3)
    n = 300  # several blocks, sorted by spin inside
    spins = rng.uniform(450, 1200, n) * rng.choice([-1, 1], n)
    st = release_states(27.0, 30.0, 0.0, spins, 0.0, 0.0, 0.0, 0.0, np.zeros(3))
    result = simulate_batch(get_preset('american'), st)
    for i in rng.choice(n, 5, replace=False):
        single = simulate_batch(
            get_preset('american'), {k: v[i:i + 1] for k, v in st.items()}, step=0.01
        )
        assert result.max_beta[i] == pytest.approx(single.max_beta[0], abs=3e-3)
        assert np.sign(result.max_beta[i]) == np.sign(single.max_beta[0])
    assert np.allclose(result.time_of_flight, 2 * 27.0 * 0.5 / 9.81, atol=1e-9)


def test_montecarlo_command(tmp_path):
    out = tmp_path / 'mc.csv'
    proc = subprocess.run(
        [
            sys.executable,
            '-m',
            'football_ros.cli',
            'montecarlo',
            '--n',
            '600',
            '--seed',
            '1',
            '--spread',
            'speed=0.5,spin_rpm=30',
            '--quiet',
            '--out',
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    with open(out) as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 600 and all(r['landed'] == '1' for r in rows)
    speeds = np.array([float(r['speed']) for r in rows])
    assert speeds.std() == pytest.approx(0.5, rel=0.15) and speeds.mean() == pytest.approx(
        27.4, abs=0.1
    )
    # The landing range follows the vacuum formula for each sampled release (paper model).
    x = np.array([float(r['landing_x']) for r in rows])
    elev = np.radians([float(r['elevation_deg']) for r in rows])
    azim = np.radians([float(r['azimuth_deg']) for r in rows])
    assert np.allclose(x, speeds**2 * np.sin(2 * elev) / 9.81 * np.cos(azim), atol=1e-5)
    assert 'landing x (downfield)' in proc.stdout and 'ball-seconds per second' in proc.stdout
    assert (tmp_path / 'mc.png').stat().st_size > 20_000
    # Angles in degrees, as the inputs: max |beta| is the single flight's (within the sampling).
    beta = np.array([float(r['max_beta_deg']) for r in rows])
    assert 3.0 < np.median(beta) < 30.0
    # The same balls as .npz: the same numbers (the CSV's rounded to 6 decimals) at full
    # precision, landed as integers.
    npz = tmp_path / 'mc.npz'
    proc = subprocess.run(
        [
            sys.executable,
            '-m',
            'football_ros.cli',
            'montecarlo',
            '--n',
            '600',
            '--seed',
            '1',
            '--spread',
            'speed=0.5,spin_rpm=30',
            '--quiet',
            '--out',
            str(npz),
            '--figure',
            'none',
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    with np.load(npz) as data:
        assert tuple(data.files) == COLUMNS and data['landed'].dtype.kind == 'i'
        assert np.abs(data['landing_x'] - x).max() <= 5.000001e-7
        assert np.abs(data['max_beta_deg'] - beta).max() <= 5.000001e-7
        assert np.abs(data['landing_x'] - x).max() > 0  # (full precision: not the CSV's)
    assert not (tmp_path / 'mc.npz.png').exists()


def test_montecarlo_with_no_spread_is_the_single_flight(tmp_path):
    out = tmp_path / 'mc.csv'
    zero = ','.join(
        f'{k}=0'
        for k in (
            'speed',
            'elevation_deg',
            'azimuth_deg',
            'spin_rpm',
            'alpha0_deg',
            'beta0_deg',
            'alpha_rate_deg_s',
            'beta_rate_deg_s',
        )
    )
    proc = subprocess.run(
        [
            sys.executable,
            '-m',
            'football_ros.cli',
            'montecarlo',
            '--n',
            '40',
            '--model',
            'full',
            '--spread',
            zero,
            '--quiet',
            '--out',
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    data = np.loadtxt(out, delimiter=',', skiprows=1)
    tr = Flight.from_release(Release(model='full')).simulate(rate=100.0)
    assert np.allclose(data[:, 8], tr.positions[-1, 0], atol=1e-5)
    assert (
        np.allclose(data[:, 9], tr.positions[-1, 1], atol=1e-5) and data[0, 9] < -0.3
    )  # drifts right


@pytest.mark.parametrize(
    'args',
    [
        ['--n', '0'],
        ['--spread', 'speed=-1'],
        ['--spread', 'mass=1'],
        ['--out', '{tmp}/no/such/folder/x.csv'],
        ['--out', '{tmp}'],
        ['--out', '{tmp}/x.txt'],
        ['--figure', '{tmp}/no/f.png'],
    ],
)
def test_montecarlo_bad_options_fail_before_any_work(tmp_path, args):
    """
    A bad option, output path included, fails at once with one line naming it.

    No flight is flown: 2M balls would take a minute.
    """
    args = [a.replace('{tmp}', str(tmp_path)) for a in args]
    if '--out' not in args:
        args += ['--out', str(tmp_path / 'x.csv')]
    proc = subprocess.run(
        [sys.executable, '-m', 'football_ros.cli', 'montecarlo', '--n', '2000000', *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and proc.stderr.startswith('football-ros: error:'), proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not list(tmp_path.glob('*.csv'))


# --- batch vs single flight over every accepted input (issue 11.2) ---------------------------


def _in(key):
    lo, hi = LIMITS[key]
    return hs.floats(lo, hi, allow_nan=False)


def _aero_in(key):
    lo, hi = AeroModel.LIMITS[key]
    return hs.floats(lo, hi, allow_nan=False)


@hs.composite
def accepted_releases(draw):
    """
    Any release the package accepts.

    Every range of LIMITS and AeroModel.LIMITS, both balls, both models and moment curves, ball
    parameters scaled by 0.5 to 2.
    """
    model = draw(hs.sampled_from(['paper', 'full']))
    aero = {}
    if model == 'full':
        aero = {
            key: draw(_aero_in(key))
            for key in (
                'c_d0',
                'c_d2',
                'c_l_alpha',
                'c_n_p_alpha',
                'c_m_q',
                'c_l_p',
                'c_m_p_alpha',
                'air_density',
            )
        }
        aero['c_m_q'] = draw(hs.sampled_from([aero['c_m_q'], -100.0]))  # the strongest damping
        aero['wind'] = [draw(_aero_in('wind')) for _ in range(3)]
    z = draw(hs.sampled_from([0.0, 2.0, draw(hs.floats(0.0, 1000.0))]))
    elevation = draw(_in('elevation_deg'))
    if z <= 0.0:
        elevation = max(abs(elevation), 0.5)
    scale = {
        key: draw(hs.floats(0.5, 2.0))
        for key in ('mass', 'diameter', 'inertia_spin', 'inertia_transverse', 'c_m_alpha')
    }
    ball = draw(hs.sampled_from(['american', 'rugby']))
    preset = get_preset(ball)
    try:
        release = _release(ball, draw, elevation, z, model, aero, preset, scale)
        Flight.from_release(release)  # flyable at the default step (limits.check_flyable)
        return release
    except ReleaseError:  # outside a combined limit (total axis offset, step x rate, ...)
        assume(False)


def _release(ball, draw, elevation, z, model, aero, preset, scale) -> Release:
    return Release(
        ball=ball,
        speed=draw(_in('speed')),
        elevation_deg=elevation,
        azimuth_deg=draw(_in('azimuth_deg')),
        spin_rpm=draw(_in('spin_rpm')),
        alpha0_deg=draw(_in('alpha0_deg')),
        beta0_deg=draw(_in('beta0_deg')),
        alpha_rate_deg_s=draw(_in('alpha_rate_deg_s')),
        beta_rate_deg_s=draw(_in('beta_rate_deg_s')),
        position=(0.0, 0.0, z),
        model=model,
        moment=draw(hs.sampled_from(['linear', 'sin2delta'])),
        ball_params={k: getattr(preset, k) * f for k, f in scale.items()},
        aero=aero,
    )


@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,  # the same 30 releases every run (CI); offline runs of 400 vary them
)
@given(accepted_releases())
def test_batch_agrees_with_the_single_flight_for_every_accepted_release(release):
    """
    Same landing (or the same position at max_time) as a tight single flight.

    The single flight: RK4 at 0.25 ms, or 0.5 / the fastest rate if shorter, inside RK4's
    stability limit of 2.8 / rate. The default step respects every fast rate (strong pitch
    damping included). Tolerance: 0.1 mm (1 us) plus the larger of the tight flight's own error
    (twice its change when its step is halved) and the error of the single flight at its
    default step: a tumbling ball hovering or gliding in an updraft is chaotic, and there
    neither integrator is exact.
    """
    states = states_of([release])
    result = simulate_batch(
        release.preset(), states, release.model, release.moment, release.aero_model()
    )
    ball, aero = resolve(release.preset(), release.model, release.aero_model())
    rate = fastest_rates(lean_states(ball, states), make_params(ball, release.moment, aero))[0]
    step = min(2.5e-4, 0.5 / rate)
    tr, half, default = (
        Flight.from_release(release, step=h).simulate(rate=50.0, duration=20.0)
        for h in (step, step / 2, 1e-3)
    )
    assert np.isfinite(
        [
            result.landing_x[0],
            result.landing_y[0],
            result.max_alpha[0],
            result.max_beta[0],
            result.max_delta[0],
        ]
    ).all()
    assume(tr.landed == half.landed)  # else the single flight does not know either
    # A Magnus moment can pump the wobble far beyond its release value (10^4 rad/s seen); where
    # the tight single flight no longer resolves it (RK4 beyond 0.5 rad per step), it is no
    # reference (test_a_wobble_pumped_by_the_magnus_moment... covers pumping).
    assume(np.linalg.norm(tr.states[:, dyn.H:dyn.H + 3], axis=1).max() * step <= 0.5)
    assert result.landed[0] == tr.landed
    own = 2.0 * np.abs(tr.positions[-1] - half.positions[-1])
    if default.landed == tr.landed and np.isfinite(default.positions[-1]).all():
        own = np.maximum(own, np.abs(tr.positions[-1] - default.positions[-1]))
        own_t = max(
            2.0 * abs(tr.times[-1] - half.times[-1]), abs(tr.times[-1] - default.times[-1])
        )
    else:
        own_t = 2.0 * abs(tr.times[-1] - half.times[-1])
    assert result.time_of_flight[0] == pytest.approx(tr.times[-1], abs=1e-6 + own_t)
    assert result.landing_x[0] == pytest.approx(tr.positions[-1, 0], abs=1e-4 + own[0])
    assert result.landing_y[0] == pytest.approx(tr.positions[-1, 1], abs=1e-4 + own[1])
    assert 0.0 <= result.max_beta[0] <= result.max_delta[0] + 1e-12 <= math.pi + 1e-12


def test_strong_pitch_damping_lands_like_the_single_flight():
    """The case of issue 11.2: c_m_q = -100 at 40 m/s used to return NaN, not landed."""
    release = Release(model='full', speed=40.0, aero={'c_m_q': -100.0})
    result = simulate_batch(
        release.preset(), states_of([release]), 'full', aero=release.aero_model()
    )
    tr = Flight.from_release(release).simulate(rate=100.0, duration=20.0)
    assert result.landed[0] and tr.landed
    assert result.landing_x[0] == pytest.approx(tr.positions[-1, 0], abs=1e-5)
    assert result.landing_y[0] == pytest.approx(tr.positions[-1, 1], abs=1e-5)


def test_a_wobble_pumped_by_the_magnus_moment_shortens_the_step_in_flight():
    """
    A slow spinner in an updraft.

    The Magnus moment pumps its transverse rate from ~0 to ~470 rad/s in 20 s, beyond any bound
    known at release. The kernel shortens the step as the rates grow (with the release's step
    it diverged to 1e38 m).
    """
    release = Release(
        speed=1.0,
        elevation_deg=0.0,
        spin_rpm=14.0,
        position=(0.0, 0.0, 2.0),
        model='full',
        ball_params={'diameter': 0.3452},
        aero={
            'c_d0': 0.0,
            'c_d2': 1.0,
            'c_l_alpha': 0.0,
            'c_m_q': 0.0,
            'c_l_p': 0.0,
            'c_m_p_alpha': 1.0,
            'air_density': 1.0,
            'wind': [0.0, 0.0, 10.0],
        },
    )
    result = simulate_batch(
        release.preset(), states_of([release]), 'full', aero=release.aero_model()
    )
    tr = Flight.from_release(release, step=1e-4).simulate(rate=10.0, duration=20.0)
    assert not result.landed[0] and not tr.landed
    assert np.abs(tr.angular_velocities[-1]).max() > 300.0  # the pumped wobble
    assert result.landing_x[0] == pytest.approx(tr.positions[-1, 0], abs=1e-6)
    assert result.landing_y[0] == pytest.approx(tr.positions[-1, 1], abs=1e-6)


@pytest.mark.parametrize(
    'aero, alpha0',
    [
        ({'c_d2': 1.0, 'air_density': 1.0, 'wind': [0.0, 0.0, -34.0]}, 0.0),  # a downdraft
        ({'c_l_alpha': 3.0, 'air_density': 2.0}, 6.0),  # steep lift, nose down
    ],
)
def test_a_release_from_the_ground_pushed_down_at_once_lands_in_both(aero, alpha0):
    """
    Land a release from the ground that the air pushes below it in the first step.

    Found by the property test: released at z = 0 (1 m/s, 0.5 deg up), the single flight used
    to fly on under the ground.
    """
    zero = dict.fromkeys(
        ('c_d0', 'c_d2', 'c_l_alpha', 'c_n_p_alpha', 'c_m_q', 'c_l_p', 'c_m_p_alpha'), 0.0
    )
    release = Release(speed=1.0, elevation_deg=0.5, alpha0_deg=alpha0, model='full',
                      ball_params={'diameter': 0.3452}, aero={**zero, **aero})
    single = Flight.from_release(release).simulate(rate=1000.0, duration=1.0)  # 1 ms steps
    result = simulate_batch(release.preset(), states_of([release]), 'full',
                            aero=AeroModel.from_mapping(release.aero))
    assert single.landed and result.landed[0]
    assert single.times[-1] < 0.02 and single.positions[-1, 2] == 0.0
    assert result.time_of_flight[0] == pytest.approx(single.times[-1], abs=2e-4)


def test_the_owned_dop853_tableau_is_the_published_one():
    """Quadrature conditions of an 8th-order method hold, and the digits are scipy's."""
    from football_ros.physics import batch as bt

    c = bt._A.sum(axis=1)
    for k in range(1, 9):  # sum_j b_j c_j^(k-1) = 1/k up to order 8
        assert bt._B @ c ** (k - 1) == pytest.approx(1.0 / k, abs=1e-14)
    for i in range(1, bt._STAGES):  # explicit: stage i uses stages before it only
        assert not np.any(bt._A[i, i:])
    try:
        from scipy.integrate._ivp import dop853_coefficients as tableau
    except ImportError:  # a scipy that has moved the file: the conditions above still hold
        return
    n = tableau.N_STAGES
    assert np.array_equal(bt._A, tableau.A[:n, :n])
    assert np.array_equal(bt._B, tableau.B)
    assert np.allclose(c, tableau.C[:n], rtol=0, atol=1e-15)
