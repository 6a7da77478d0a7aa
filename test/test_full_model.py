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

"""The full model (drag, lift, Magnus, damping, wind) against physics it must show."""

import dataclasses
import math

from football_ros.physics import dynamics as dyn
from football_ros.physics import Flight, frames, get_preset, Release, ReleaseError
from football_ros.physics.aero import AeroModel, air_density, max_valid_delta, out_of_validity
from football_ros.physics.modes import dynamic_stability
import numpy as np
import pytest

G = 9.81
ZERO = {
    'c_d0': 0.0, 'c_d2': 0.0, 'c_l_alpha': 0.0, 'c_n_p_alpha': 0.0, 'c_m_q': 0.0, 'c_l_p': 0.0,
    'c_m_p_alpha': 0.0,
}


def fly(release, **kw):
    return Flight.from_release(release).simulate(
        rate=kw.get('rate', 100.0), duration=kw.get('duration', 10.0)
    )


@pytest.mark.parametrize(
    'aero',
    [
        ZERO,
        {
            'drag': False,
            'lift': False,
            'magnus': False,
            'pitch_damping': False,
            'spin_damping': False,
        },
    ],
)
def test_zero_coefficients_reduce_exactly_to_the_paper_model(aero):
    base = {'alpha0_deg': 3.0, 'beta0_deg': -2.0, 'alpha_rate_deg_s': 25.0, 'spin_rpm': 550.0}
    paper = fly(Release(**base))
    full = fly(Release(model='full', aero=aero, **base))
    assert np.array_equal(paper.times, full.times)
    assert np.max(np.abs(paper.states - full.states)) <= 1e-15 * np.max(np.abs(paper.states))


def test_energy_falls_with_drag():
    tr = fly(Release(model='full', aero={'lift': False, 'magnus': False}), rate=50)
    energy = 0.5 * np.sum(tr.velocities**2, axis=1) + G * tr.positions[:, 2]
    assert np.all(np.diff(energy) < 0)
    assert energy[-1] < 0.85 * energy[0]  # about a quarter of the energy goes into the air
    paper = fly(Release())
    assert tr.positions[-1, 0] < paper.positions[-1, 0] - 5.0  # a shorter pass


@pytest.mark.parametrize('spin, side', [(600.0, -1.0), (-600.0, 1.0)])
def test_spiral_drifts_to_the_side_its_nose_points(spin, side):
    """Right-handed spiral: nose right of the velocity (beta > 0), lift pushes right (-y)."""
    tr = fly(Release(model='full', spin_rpm=spin))
    assert tr.landed and side * tr.positions[-1, 1] > 0.3  # tens of centimetres
    no_lift = fly(Release(model='full', spin_rpm=spin, aero={'lift': False}))
    assert abs(no_lift.positions[-1, 1]) < 1e-9  # Magnus is off by default: lift alone drifts


def test_spin_decays_with_spin_damping():
    tr = fly(Release(model='full'), rate=50)
    spin = np.sum(tr.angular_velocities * tr.axes, axis=1)
    assert np.all(np.diff(spin) < 0) and spin[-1] < 0.95 * spin[0]
    # The stored h1 and h.s agree (the projection keeps them together while h1 changes).
    assert np.max(np.abs(tr.spin_momentum - tr.states[:, 13])) < 1e-12
    kept = fly(Release(model='full', aero={'spin_damping': False}), rate=50)
    spin_kept = np.sum(kept.angular_velocities * kept.axes, axis=1)
    assert np.allclose(spin_kept, spin_kept[0], rtol=1e-12)


@pytest.mark.parametrize('c_m_q, grows', [(0.0, False), (-0.1, False), (-2.0, True)])
def test_wobble_grows_or_decays_as_mccoy_predicts(c_m_q, grows):
    """Too much pitch damping against little lift makes the slow mode grow (S_d small)."""
    from football_ros.cli import modes_report

    release = Release(model='full', aero={'c_m_q': c_m_q})
    report = modes_report(release)
    assert (report['slow_damping_rate'] > 0) == grows
    tr = fly(release, rate=200)
    early, late = tr.times < 1.2, tr.times > 1.5
    ratio = np.max(np.abs(tr.aero_angles[late, 0])) / np.max(np.abs(tr.aero_angles[early, 0]))
    assert ratio > 1.5 if grows else ratio < 1.0


def test_crosswind_carries_the_ball_downwind():
    wind = fly(Release(model='full', aero={'wind': [0.0, -5.0, 0.0]}))  # blowing toward -y
    calm = fly(Release(model='full'))
    assert wind.positions[-1, 1] < calm.positions[-1, 1] - 0.5


def test_air_density_from_altitude_and_temperature():
    assert air_density(0.0, 15.0) == pytest.approx(1.225, abs=1e-3)
    assert air_density(0.0) == pytest.approx(1.225, abs=1e-3)
    # Denver, 15 C: ISA pressure 83431 Pa / (287.05 J/(kg K) * 288.15 K)
    assert air_density(1609.0, 15.0) == pytest.approx(83431 / (287.05 * 288.15), rel=1e-4)
    # No temperature: the ISA lapse, 15 C - 6.5 K/km * 1.609 km = 4.54 C (ISA tables: 1.0467).
    isa = 83431 / (287.05 * (288.15 - 0.0065 * 1609.0))
    assert air_density(1609.0) == pytest.approx(isa, rel=1e-4)
    assert isa == pytest.approx(1.0467, abs=2e-4)
    thin = Flight.from_release(Release(model='full', aero={'altitude_m': 1609.0}))
    assert thin.ball.air_density == pytest.approx(isa, rel=1e-4)
    assert thin.modes.m_alpha == pytest.approx(190.91 * thin.ball.air_density / 1.225, rel=1e-4)
    warm = Flight.from_release(
        Release(model='full', aero={'altitude_m': 1609.0, 'temperature_c': 15.0})
    )
    assert warm.ball.air_density == pytest.approx(83431 / (287.05 * 288.15), rel=1e-4)


def _measured_mode_exponents(aero, rate=200.0, duration=1.5):
    """
    Return complex exponents of the two modes of x = s2 + i s3, by Prony's method.

    In a flight without gravity or drag (constant U: the linear equation has constant
    coefficients).
    """
    release = Release(
        model='full',
        aero=dict(drag=False, spin_damping=False, **aero),
        alpha0_deg=2.0,
        beta0_deg=1.0,
        alpha_rate_deg_s=40.0,
        position=(0.0, 0.0, 50.0),
    )
    flight = Flight.from_release(release)
    flight.params[dyn.P_GRAVITY] = 0.0
    tr = flight.simulate(rate=rate, duration=duration)
    comps = frames.to_velocity_frame(tr.axes, tr.air_velocities)
    x = comps[:, 1] + 1j * comps[:, 2]
    coef = np.linalg.lstsq(np.column_stack([x[1:-1], x[:-2]]), x[2:], rcond=None)[0]
    sigma = np.log(np.roots([1.0, -coef[0], -coef[1]])) * rate
    sigma = sigma[np.argsort(-np.abs(sigma.imag))]  # fast first
    predicted = dynamic_stability(flight.ball, 27.4, release.initial_state().spin, flight.aero)
    return sigma, predicted


@pytest.mark.parametrize(
    'c_m_p_alpha, c_n_p_alpha', [(0.0, 0.0), (0.03, 0.0), (-0.03, 0.0), (0.0, 0.3), (0.03, 0.3)]
)
def test_damping_rates_with_magnus_match_flights(c_m_p_alpha, c_n_p_alpha):
    """
    Check that McCoy's T carries the Magnus MOMENT.

    The rates measured in integrated flights agree within 2 % (measured 0.1-1 %); the Magnus
    force leaves them (and S_d) unchanged.
    """
    sigma, pred = _measured_mode_exponents(
        {'c_m_p_alpha': c_m_p_alpha, 'c_n_p_alpha': c_n_p_alpha}
    )
    assert sigma[0].real == pytest.approx(pred.fast_damping_rate, rel=0.02)
    assert sigma[1].real == pytest.approx(pred.slow_damping_rate, rel=0.02)
    # Independent check: rates without any Magnus term, measured the same way, and the shift
    # the Magnus moment must give: d(lambda_f) = -d(lambda_s) = (P/root) dT (V/D) per McCoy.
    base, base_pred = _measured_mode_exponents({})
    ball = get_preset('american')
    area = math.pi * ball.diameter**2 / 4
    d_t = (
        1.225
        * area
        * ball.diameter
        / (2 * ball.mass)
        * ball.mass
        * ball.diameter**2
        / ball.inertia_spin
        * c_m_p_alpha
    )
    p_nd = ball.inertia_ratio * 600 * 2 * math.pi / 60 * ball.diameter / 27.4
    m_nd = ball.moment_coefficient() * ball.diameter**2
    shift = p_nd * d_t / math.sqrt(p_nd**2 - 4 * m_nd) * 27.4 / ball.diameter
    assert sigma[0].real - base[0].real == pytest.approx(shift, abs=0.01)
    assert sigma[1].real - base[1].real == pytest.approx(-shift, abs=0.01)
    if c_m_p_alpha == 0.0:
        assert pred.s_d == pytest.approx(base_pred.s_d, rel=1e-12)


def test_magnus_force_has_the_classical_direction():
    """
    A positive C_Npalpha pushes along p (s x u).

    A right-handed spiral flying nose-right (beta > 0, i.e. toward -y for a throw along +x) is
    pushed up, a left-handed one down.
    """
    ball = get_preset('american')
    aero = AeroModel(
        drag=False, lift=False, pitch_damping=False, spin_damping=False, c_n_p_alpha=0.2
    )
    params = dyn.make_params(ball, 'linear', aero)
    v = (25.0, 0.0, 0.0)
    beta = math.radians(5.0)
    s = (math.cos(beta), -math.sin(beta), 0.0)  # nose right of the velocity
    for spin in (60.0, -60.0):
        h1 = ball.inertia_ratio * spin
        h = tuple(h1 * c for c in s)
        ax, ay, az, *_ = dyn.loads(v, s, h, h1, params)
        # Independent: F/m = rho S / (2m) U^2 (p D / U) C_Npa (s x u_hat).
        expected = (
            1.225
            * ball.reference_area
            / (2 * ball.mass)
            * 25.0
            * spin
            * ball.diameter
            * 0.2
            * np.cross(s, np.array(v) / 25.0)
        )
        assert (ax, ay, az + G) == pytest.approx(tuple(expected), abs=1e-12)
        assert np.sign(az + G) == np.sign(spin)


def test_lift_follows_sin_2_delta():
    ball = get_preset('american')
    aero = AeroModel(drag=False, magnus=False, pitch_damping=False, spin_damping=False)
    params = dyn.make_params(ball, 'linear', aero)
    fk = 1.225 * ball.reference_area / (2 * ball.mass)
    for deg in (5.0, 30.0, 45.0, 70.0, 90.0):
        d = math.radians(deg)
        s = (math.cos(d), 0.0, math.sin(d))
        ax, ay, az, *_ = dyn.loads((20.0, 0.0, 0.0), s, (0.0, 0.0, 0.0), 0.0, params)
        # Lift perpendicular to u, magnitude q C_L / m with C_L = C_Lalpha / 2 sin 2 delta.
        assert ax == pytest.approx(0.0, abs=1e-12)
        assert az + G == pytest.approx(fk * 400.0 * 0.40 / 2 * math.sin(2 * d), abs=1e-12)


def test_aero_angles_are_relative_to_the_air():
    """
    Galilean check.

    A flight in a wind W equals the still-air flight released at v0 - W seen from a frame
    moving with W; angles and the linear theory are identical, positions shift.
    """
    ball = get_preset('american')
    st = Release(
        alpha0_deg=3.0, beta0_deg=-2.0, alpha_rate_deg_s=20.0, position=(0, 0, 20.0)
    ).initial_state()
    wind = np.array([-4.0, 3.0, 0.5])
    calm_st = dataclasses.replace(st, velocity=st.velocity - wind)
    windy = Flight(ball, st, 'full', aero=AeroModel(wind=tuple(wind))).simulate(
        rate=100, duration=1.5
    )
    calm = Flight(ball, calm_st, 'full', aero=AeroModel()).simulate(rate=100, duration=1.5)
    assert np.max(np.abs(windy.aero_angles - calm.aero_angles)) < 1e-9
    assert np.max(np.abs(windy.aero_angles_linear - calm.aero_angles_linear)) < 1e-12
    assert np.max(np.abs(windy.aero_angles_quasi_steady - calm.aero_angles_quasi_steady)) < 1e-9
    assert np.max(np.abs(windy.positions - calm.positions - wind * windy.times[:, None])) < 1e-9
    ref = frames.aero_angles(windy.axes, windy.velocities, wind)
    assert np.max(np.abs(windy.aero_angles - ref)) < 1e-12
    # The ground-velocity angles differ by degrees here: the wind matters.
    assert np.max(np.abs(frames.aero_angles(windy.axes, windy.velocities) - ref)) > 0.05
    # Real-time samples agree with the headless table.
    flight = Flight(ball, st, 'full', aero=AeroModel(wind=tuple(wind)))
    sample = flight.sample(0.5)
    assert sample.aero_angles == pytest.approx(windy.aero_angles[50], abs=1e-12)


def test_linear_moment_range_is_where_it_leaves_rae_and_streit_by_10_percent():
    """
    Kernel's linear torque against the sin2delta one: ratio 1/cos(delta).

    The sin2delta torque is Rae & Streit's 0.165 sin 2 delta scaled to the slope; the ratio is
    1.10 at the 24.6 deg limit of VALIDITY.
    """
    from football_ros.physics.aero import VALIDITY

    ball = get_preset('american')
    lin, curve = dyn.make_params(ball, 'linear'), dyn.make_params(ball, 'sin2delta')
    limit = VALIDITY['moment_linear'].max_delta_deg
    for deg, ratio in ((10.0, None), (limit, 1.10), (30.0, None)):
        d = math.radians(deg)
        s = (math.cos(d), 0.0, math.sin(d))
        m_lin = np.array(dyn.loads((20.0, 0.0, 0.0), s, (0, 0, 0), 0.0, lin)[3:6])
        m_rs = np.array(dyn.loads((20.0, 0.0, 0.0), s, (0, 0, 0), 0.0, curve)[3:6])
        # Independent magnitude: k U^2 sin(delta) for the linear slope.
        assert np.linalg.norm(m_lin) == pytest.approx(
            ball.moment_coefficient() * 400.0 * math.sin(d), rel=1e-12
        )
        got = np.linalg.norm(m_lin) / np.linalg.norm(m_rs)
        assert got == pytest.approx(1.0 / math.cos(d), rel=1e-12)
        if ratio:
            assert got == pytest.approx(ratio, abs=1e-3)
    assert limit == pytest.approx(math.degrees(math.acos(1 / 1.1)), abs=0.05)


def test_validity_ranges_flag_large_angles():
    aero = AeroModel()
    assert out_of_validity(math.radians(10.0), 'full', 'sin2delta', aero) == []
    msgs = out_of_validity(math.radians(30.0), 'full', 'linear', aero)
    assert len(msgs) == 2 and '24.6 deg' in msgs[0]  # linear moment and pitch damping (Magnus off)
    assert any('pitch damping' in m for m in msgs)
    msgs = out_of_validity(math.radians(55.0), 'full', 'sin2delta', aero)
    assert any('C_Malpha/2 sin 2 delta' in m for m in msgs) and any('lift' in m for m in msgs)
    with_ball = out_of_validity(math.radians(55.0), 'full', 'sin2delta', aero,
                                get_preset('american'))
    assert any('0.165 sin 2 delta' in m for m in with_ball)  # the ball's own C_Malpha / 2
    assert not any('drag' in m for m in msgs)  # drag covers 0-90 deg
    assert len(out_of_validity(math.radians(95.0), 'full', 'sin2delta', aero)) == 4
    assert out_of_validity(math.radians(20.0), 'paper', 'linear') == []
    assert out_of_validity(float('nan')) != []
    assert max_valid_delta('full', 'linear', aero) == pytest.approx(math.radians(20.0))
    assert max_valid_delta('paper', 'sin2delta') == pytest.approx(math.radians(50.0))
    for deg in (19.0, 21.0, 49.0, 51.0):
        assert (out_of_validity(math.radians(deg), 'full', 'sin2delta', aero) == []) == (
            math.radians(deg) <= max_valid_delta('full', 'sin2delta', aero)
        )


def _mccoy_rates(ball, speed, spin, c_l_alpha=0.40, c_d0=0.0, c_m_q=-0.10, c_m_p_alpha=0.0):
    """
    Return McCoy's per-calibre rates, times V/D.

    lambda_F,S = -[H -+ P (2T - H)/sqrt(P^2 - 4M)]/2.
    """
    area = math.pi * ball.diameter**2 / 4
    fk_d = 1.225 * area * ball.diameter / (2 * ball.mass)
    h_nd = fk_d * (
        c_l_alpha - c_d0 - ball.mass * ball.diameter**2 / ball.inertia_transverse * c_m_q
    )
    t_nd = fk_d * (c_l_alpha + ball.mass * ball.diameter**2 / ball.inertia_spin * c_m_p_alpha)
    p_nd = ball.inertia_ratio * spin * ball.diameter / speed
    m_nd = ball.moment_coefficient() * ball.diameter**2
    root = math.sqrt(p_nd**2 - 4 * m_nd)
    lam_f = -0.5 * (h_nd - p_nd * (2 * t_nd - h_nd) / root)
    lam_s = -0.5 * (h_nd + p_nd * (2 * t_nd - h_nd) / root)
    return lam_f * speed / ball.diameter, lam_s * speed / ball.diameter, 2 * t_nd / h_nd


def test_mccoy_factors_are_consistent():
    ball = get_preset('american')
    spin = 600 * 2 * math.pi / 60
    d = dynamic_stability(ball, 27.4, spin, AeroModel())
    modes = Flight.from_release(Release()).modes
    assert d.s_g == pytest.approx(modes.gyroscopic_stability_factor, rel=1e-12)
    # S_d is McCoy's 2T/H, H with the -C_D0 of his per-calibre equation.
    assert d.s_d == pytest.approx(_mccoy_rates(ball, 27.4, spin, c_d0=0.055)[2], rel=1e-12)
    assert d.dynamically_stable and d.fast_damping_rate < 0 and d.slow_damping_rate < 0
    # Without drag and spin damping (constant coefficients) the time-domain rates are McCoy's
    # lambda V / D (to 2e-5: his formula is first order in H and T, the roots are exact), and
    # the frequencies the full model's (close to w_f, w_s).
    calm = dynamic_stability(ball, 27.4, spin, AeroModel(drag=False, spin_damping=False))
    lam_f, lam_s, _ = _mccoy_rates(ball, 27.4, spin)
    assert calm.fast_damping_rate == pytest.approx(lam_f, rel=1e-4)
    assert calm.slow_damping_rate == pytest.approx(lam_s, rel=1e-4)
    assert calm.fast_frequency == pytest.approx(modes.omega_fast, rel=0.01)
    assert calm.slow_frequency == pytest.approx(modes.omega_slow, rel=0.01)
    # With drag on, McCoy's lambda V / D (P held constant per calibre) is not the decay in
    # time: the defaults differ from it by 13 % (fast) and 5 % (slow).
    lam_f, lam_s, _ = _mccoy_rates(ball, 27.4, spin, c_d0=0.055)
    assert abs(d.fast_damping_rate / lam_f - 1) > 0.1
    undamped = dynamic_stability(ball, 27.4, spin, AeroModel().without_extras())
    assert math.isnan(undamped.s_d) and not undamped.dynamically_stable
    assert undamped.fast_damping_rate == pytest.approx(0.0, abs=1e-12)


def _measured_rates_with_drag(aero, spin_rpm, t1=0.2, t2=2.8, half=0.15, rate=500.0):
    """
    Each mode's amplitude rate [1/s] in an integrated flight without gravity (drag slows it).

    Amplitudes fitted (Prony exponents, then least squares) in windows around t1 and t2; and
    the package's rates averaged over the same interval of the same flight.
    """
    release = Release(
        model='full',
        aero=aero,
        spin_rpm=spin_rpm,
        alpha0_deg=2.0,
        beta0_deg=1.0,
        alpha_rate_deg_s=40.0,
        position=(0.0, 0.0, 500.0),
    )
    flight = Flight.from_release(release)
    flight.params[dyn.P_GRAVITY] = 0.0
    tr = flight.simulate(rate=rate, duration=t2 + half + 0.05)
    comps = frames.to_velocity_frame(tr.axes, tr.air_velocities)
    x = comps[:, 1] + 1j * comps[:, 2]
    amplitudes = []
    for centre in (t1, t2):
        sel = np.abs(tr.times - centre) <= half
        xs, ts = x[sel], tr.times[sel] - centre
        coef = np.linalg.lstsq(np.column_stack([xs[1:-1], xs[:-2]]), xs[2:], rcond=None)[0]
        sigma = np.log(np.roots([1.0, -coef[0], -coef[1]])) * rate
        sigma = sigma[np.argsort(-np.abs(sigma.imag))]  # fast first
        amp = np.linalg.lstsq(np.exp(np.outer(ts, sigma)), xs, rcond=None)[0]
        amplitudes.append(np.abs(amp))
    measured = np.log(amplitudes[1] / amplitudes[0]) / (t2 - t1)
    speeds = np.linalg.norm(tr.air_velocities, axis=1)
    spins = tr.states[:, 13] / flight.ball.inertia_ratio
    inside = np.flatnonzero((tr.times >= t1) & (tr.times <= t2))[::5]
    predicted = np.mean(
        [
            [
                getattr(dynamic_stability(flight.ball, speeds[i], spins[i], flight.aero), k)
                for k in ('fast_damping_rate', 'slow_damping_rate')
            ]
            for i in inside
        ],
        axis=0,
    )
    return measured, predicted


@pytest.mark.parametrize(
    'aero, expected',
    [
        ({'spin_damping': False}, (-0.356, -0.377)),
        ({}, (-0.311, -0.373)),
        ({'spin_damping': False, 'c_m_p_alpha': 0.03}, (-0.128, -0.605)),
    ],
)
@pytest.mark.parametrize('spin_rpm', [600.0, -600.0])
def test_damping_rates_with_drag_match_flights(aero, expected, spin_rpm):
    """
    Drag on: the per-second rates agree with integrated flights to 1 %.

    Rates in the time domain with the WKB terms, against the decay measured in integrated
    flights (measured 0.1-0.6 %), for both spin directions; the pre-fix McCoy lambda V / D gave
    -0.278/-0.367, -0.277/-0.369, -0.049/-0.597.
    """
    measured, predicted = _measured_rates_with_drag(aero, spin_rpm)
    assert measured == pytest.approx(expected, abs=0.003)
    assert predicted == pytest.approx(measured, rel=0.01)


@pytest.mark.parametrize(
    'aero, match',
    [
        ({'c_d0': -0.1}, 'outside'),
        ({'wind': [1, 2]}, 'wind'),
        ({'drag': 'yes'}, 'true or false'),
        ({'colour': 1}, 'unknown aero'),
        ({'c_m_q': 0.5}, 'outside'),
        ({'air_density': float('nan')}, 'finite'),
    ],
)
def test_bad_aero_settings(aero, match):
    with pytest.raises(ReleaseError, match=match):
        Release(model='full', aero=aero)


def test_aero_round_trip():
    aero = AeroModel(wind=(1.0, -2.0, 0.0), drag=False, c_l_alpha=0.3)
    assert AeroModel.from_mapping(aero.to_mapping()) == aero
    assert dataclasses.replace(aero, drag=True).drag


@pytest.mark.parametrize('aero', [{}, {'c_m_p_alpha': 0.03, 'c_n_p_alpha': 0.3}])
def test_quasi_steady_theory_carries_the_full_models_damping(aero):
    """
    No gravity or drag (constant coefficients).

    The full model's own linear equation (lift, damping, Magnus) follows the integrated wobble
    to 3e-3 rad of a 0.05 rad wobble over 3 s (measured 1.4e-3 / 1.5e-3), where the paper's
    undamped frozen theory is off by 0.035-0.044 rad.
    """
    from football_ros.physics import linear_modes

    release = Release(
        model='full',
        aero=dict(drag=False, spin_damping=False, **aero),
        alpha0_deg=3.0,
        beta_rate_deg_s=20.0,
        position=(0, 0, 10),
    )
    flight = Flight.from_release(release)
    flight.params[dyn.P_GRAVITY] = 0.0
    flight.modes = linear_modes(flight.ball, flight.initial, gravity=0.0)
    tr = flight.simulate(rate=500, duration=3.0)
    nl = tr.aero_angles[:, :2]
    assert np.max(np.abs(tr.aero_angles_quasi_steady - nl)) < 3e-3
    assert np.max(np.abs(tr.aero_angles_linear - nl)) > 0.03


@pytest.mark.parametrize('ball, ratio', [('american', 0.15), ('rugby', 0.5)])
def test_quasi_steady_tracks_full_flights_better(ball, ratio):
    """
    Nominal full-model flights, rms over alpha, beta.

    Measured American 0.0057 vs 0.0646 rad, rugby 0.088 vs 0.222 rad (0.0111 and 0.093 before
    the equilibrium's drift was added).
    """
    tr = Flight.from_release(Release(ball=ball, model='full')).simulate(rate=1000.0, duration=10.0)

    def rms(a):
        return float(np.sqrt(np.mean((a - tr.aero_angles[:, :2]) ** 2)))

    assert rms(tr.aero_angles_quasi_steady) < ratio * rms(tr.aero_angles_linear)


def test_modes_flag_follows_the_mode_rates_not_mccoy():
    """
    C_Mpalpha = 0.036: both of the package's rates decay, McCoy's criterion says unstable.

    The flag follows the rates (the measured rates of flights agree with them, see
    test_rates_match_integrated_flights_with_drag); McCoy's S_d stays as a labelled reference.
    """
    from football_ros.physics.modes import modes_report

    report = modes_report(Release(model='full', aero={'c_m_p_alpha': 0.036}))
    assert report['fast_damping_rate'] == pytest.approx(-0.0194, abs=5e-4)
    assert report['slow_damping_rate'] == pytest.approx(-0.7222, abs=5e-4)
    assert report['dynamically_stable'] is True
    assert report['mccoy_dynamically_stable'] is False
    assert report['dynamic_stability_factor'] == pytest.approx(1.727, abs=1e-3)
    # A 10 m/s headwind raises the air speed to 36.4 m/s: the fast mode then grows.
    windy = modes_report(
        Release(model='full', aero={'c_m_p_alpha': 0.036, 'wind': [-10.0, 0.0, 0.0]})
    )
    assert windy['fast_damping_rate'] > 0 and windy['dynamically_stable'] is False


def test_modes_are_the_flown_modes_against_the_air():
    """With wind the modes use u = v - wind, exactly as the Flight that simulate flies."""
    from football_ros.physics.modes import modes_report

    release = Release(model='full', aero={'wind': [-10.0, 0.0, 0.0]})
    report = modes_report(release)
    v = 27.4 * np.array([math.cos(math.radians(30)), 0.0, math.sin(math.radians(30))])
    air = v - np.array([-10.0, 0.0, 0.0])
    speed = float(np.linalg.norm(air))
    assert report['speed'] == pytest.approx(speed, rel=1e-12)
    assert speed == pytest.approx(36.405, abs=1e-3)
    assert report['flight_path_angle'] == pytest.approx(math.atan2(air[2], air[0]), rel=1e-12)
    assert report['m_alpha'] == pytest.approx(190.90987 * (speed / 27.4) ** 2, rel=1e-6)
    flight = Flight.from_release(release)
    assert report['omega_fast'] == flight.modes.omega_fast
    assert report['equilibrium_sideslip'] == flight.modes.equilibrium_sideslip
    assert report['c1'] == [flight.modes.c1.real, flight.modes.c1.imag]
    # The full model's own frequencies are its local exponents at release.
    from football_ros.physics.linear_theory import local_exponents

    sig1, sig2, _, _, x_p = local_exponents(flight.params, air, flight.modes.h1)
    assert report['full']['omega_fast'] == pytest.approx(sig1.imag, rel=1e-9)
    assert report['full']['omega_slow'] == pytest.approx(sig2.imag, rel=1e-9)
    assert report['full']['equilibrium_sideslip'] == pytest.approx(x_p.imag, rel=1e-12)
    # Every extra term off: the full model's numbers are the paper's.
    bare = modes_report(Release(model='full', aero=AeroModel().without_extras().to_mapping()))
    assert bare['full']['omega_fast'] == pytest.approx(bare['omega_fast'], rel=1e-12)
    assert bare['full']['equilibrium_sideslip'] == pytest.approx(
        bare['equilibrium_sideslip'], rel=1e-12
    )


def test_modes_rates_with_the_speed_change_of_gravity():
    """
    At 30 deg gravity slows the ball by g sin(Phi): the paper model's amplitudes then change.

    For the paper's model the rate is -Re(D'/D)/2 = 2 k U U' / D^2 with D^2 = h1^2 - 4 k U^2
    and U' = -g sin(Phi): -0.1008 1/s for the nominal pass (level flight: 0).
    """
    from football_ros.physics.modes import modes_report

    paper = modes_report(Release())
    k = paper['m_alpha'] / 27.4**2
    expected = 2 * k * 27.4 * (-G * 0.5) / (paper['h1'] ** 2 - 4 * paper['m_alpha'])
    assert paper['fast_damping_rate'] == 0.0 and paper['slow_damping_rate'] == 0.0
    assert paper['fast_damping_rate_gravity'] == pytest.approx(expected, rel=1e-9)
    assert expected == pytest.approx(-0.1008, abs=1e-4)
    full = modes_report(Release(model='full'))
    assert full['fast_damping_rate_gravity'] < full['fast_damping_rate'] < 0
    assert full['slow_damping_rate_gravity'] < full['slow_damping_rate'] < 0


def test_modes_refuses_a_release_moving_with_the_wind_as_flight_does():
    from football_ros.physics.modes import modes_report

    v = 27.4 * np.array([math.cos(math.radians(30)), 0.0, math.sin(math.radians(30))])
    release = Release(model='full', aero={'wind': [float(c) for c in v]})
    with pytest.raises(ReleaseError, match='moves with the wind'):
        modes_report(release)
    with pytest.raises(ReleaseError, match='moves with the wind'):
        Flight.from_release(release)


@pytest.mark.parametrize(
    'release',
    [
        Release(),
        Release(model='full'),
        Release(model='full', elevation_deg=45.0),
        Release(ball='rugby', model='full'),
    ],
)
def test_gravity_rates_are_the_flown_flight_s_rates_at_release(release):
    """
    The *_gravity pair equals the WKB rates of the integrated flight's own U(t), h1(t) at t = 0.

    Re(sigma) - Re(D_c'/D_c)/2 +- Re(B'/(2 i D_c)) with the derivatives taken by central
    differences along the flight (0.1 ms samples): the speed change at release is drag plus
    g sin(Phi), as modes.gravity_speed_rate says (measured agreement: 3e-5 1/s).
    """
    from football_ros.physics.linear_theory import local_exponents
    from football_ros.physics.modes import modes_report

    flight = Flight.from_release(release)
    tr = flight.simulate(rate=10000.0, duration=0.01)
    sig1, sig2, b, d_c, _ = local_exponents(flight.params, tr.air_velocities, tr.states[:, 13])
    dt = tr.times[1] - tr.times[0]
    common = -0.5 * ((np.log(d_c[2]) - np.log(d_c[0])) / (2 * dt)).real
    wkb = ((b[2] - b[0]) / (2 * dt) / (2j * d_c[1])).real
    report = modes_report(release)
    assert report['fast_damping_rate_gravity'] == pytest.approx(
        sig1[1].real + common + wkb, abs=2e-4
    )
    assert report['slow_damping_rate_gravity'] == pytest.approx(
        sig2[1].real + common - wkb, abs=2e-4
    )


def test_mccoy_unstable_ball_whose_modes_decay_in_the_integrated_flight():
    """
    C_Mpalpha = 0.036: McCoy's criterion says unstable, the integrated flight's wobble decays.

    Measured in a flight with drag (no gravity, 0.2-2.8 s): -0.028 and -0.657 1/s against the
    package's -0.027 and -0.658: both modes decay, as the flag (which follows the rates) says.
    """
    from football_ros.physics.modes import dynamic_stability

    aero = {'c_m_p_alpha': 0.036}
    ball = get_preset('american')
    d = dynamic_stability(ball, 27.4, 600 * 2 * math.pi / 60, AeroModel(**aero))
    assert not d.mccoy_stable and d.dynamically_stable
    measured, predicted = _measured_rates_with_drag(aero, 600.0)
    assert measured[0] < 0 and measured[1] < 0
    assert measured == pytest.approx(predicted, abs=0.01)
