"""The full model (drag, lift, Magnus, damping, wind) against physics it must show."""

import dataclasses
import math

import numpy as np
import pytest

from football_ros.physics import Flight, Release, ReleaseError, get_preset
from football_ros.physics.aero import AeroModel, air_density, dynamic_stability

G = 9.81
ZERO = dict(c_d0=0.0, c_d2=0.0, c_l_alpha=0.0, c_n_p_alpha=0.0, c_m_q=0.0, c_l_p=0.0, c_m_p_alpha=0.0)


def fly(release, **kw):
    return Flight.from_release(release).simulate(rate=kw.get("rate", 100.0), duration=kw.get("duration", 10.0))


@pytest.mark.parametrize("aero", [ZERO, {"drag": False, "lift": False, "magnus": False,
                                         "pitch_damping": False, "spin_damping": False}])
def test_zero_coefficients_reduce_exactly_to_the_paper_model(aero):
    base = dict(alpha0_deg=3.0, beta0_deg=-2.0, alpha_rate_deg_s=25.0, spin_rpm=550.0)
    paper = fly(Release(**base))
    full = fly(Release(model="full", aero=aero, **base))
    assert np.array_equal(paper.times, full.times)
    assert np.max(np.abs(paper.states - full.states)) <= 1e-15 * np.max(np.abs(paper.states))


def test_energy_falls_with_drag():
    tr = fly(Release(model="full", aero={"lift": False, "magnus": False}), rate=50)
    energy = 0.5 * np.sum(tr.velocities ** 2, axis=1) + G * tr.positions[:, 2]
    assert np.all(np.diff(energy) < 0)
    assert energy[-1] < 0.85 * energy[0]  # about a quarter of the energy goes into the air
    paper = fly(Release())
    assert tr.positions[-1, 0] < paper.positions[-1, 0] - 5.0  # a shorter pass


@pytest.mark.parametrize("spin, side", [(600.0, -1.0), (-600.0, 1.0)])
def test_spiral_drifts_to_the_side_its_nose_points(spin, side):
    """Right-handed spiral: nose right of the velocity (beta > 0), lift pushes right (-y)."""
    tr = fly(Release(model="full", spin_rpm=spin))
    assert tr.landed and side * tr.positions[-1, 1] > 0.3  # tens of centimetres
    no_lift = fly(Release(model="full", spin_rpm=spin, aero={"lift": False}))
    assert abs(no_lift.positions[-1, 1]) < 1e-9  # Magnus is off by default: lift alone drifts


def test_spin_decays_with_spin_damping():
    tr = fly(Release(model="full"), rate=50)
    spin = np.sum(tr.angular_velocities * tr.axes, axis=1)
    assert np.all(np.diff(spin) < 0) and spin[-1] < 0.95 * spin[0]
    # The stored h1 and h.s agree (the projection keeps them together while h1 changes).
    assert np.max(np.abs(tr.spin_momentum - tr.states[:, 13])) < 1e-12
    kept = fly(Release(model="full", aero={"spin_damping": False}), rate=50)
    spin_kept = np.sum(kept.angular_velocities * kept.axes, axis=1)
    assert np.allclose(spin_kept, spin_kept[0], rtol=1e-12)


@pytest.mark.parametrize("c_m_q, grows", [(0.0, False), (-0.1, False), (-2.0, True)])
def test_wobble_grows_or_decays_as_mccoy_predicts(c_m_q, grows):
    """Too much pitch damping against little lift makes the slow mode grow (S_d small)."""
    from football_ros.cli import modes_report

    release = Release(model="full", aero={"c_m_q": c_m_q})
    report = modes_report(release)
    assert (report["slow_damping_rate"] > 0) == grows
    tr = fly(release, rate=200)
    early, late = tr.times < 1.2, tr.times > 1.5
    ratio = np.max(np.abs(tr.aero_angles[late, 0])) / np.max(np.abs(tr.aero_angles[early, 0]))
    assert ratio > 1.5 if grows else ratio < 1.0


def test_crosswind_carries_the_ball_downwind():
    wind = fly(Release(model="full", aero={"wind": [0.0, -5.0, 0.0]}))  # blowing toward -y
    calm = fly(Release(model="full"))
    assert wind.positions[-1, 1] < calm.positions[-1, 1] - 0.5


def test_air_density_from_altitude_and_temperature():
    assert air_density(0.0, 15.0) == pytest.approx(1.225, abs=1e-3)
    # Denver, 15 C: ISA pressure 83431 Pa / (287.05 J/(kg K) * 288.15 K)
    assert air_density(1609.0, 15.0) == pytest.approx(83431 / (287.05 * 288.15), rel=1e-4)
    thin = Flight.from_release(Release(model="full", aero={"altitude_m": 1609.0}))
    assert thin.ball.air_density == pytest.approx(air_density(1609.0, 15.0))
    assert thin.modes.m_alpha == pytest.approx(190.91 * thin.ball.air_density / 1.225, rel=1e-4)


def test_mccoy_factors_are_consistent():
    ball = get_preset("american")
    spin = 600 * 2 * math.pi / 60
    d = dynamic_stability(ball, 27.4, spin, AeroModel())
    modes = Flight.from_release(Release()).modes
    assert d.s_g == pytest.approx(modes.gyroscopic_stability_factor, rel=1e-12)
    # lambda_F + lambda_S = -H (per calibre), independent of P.
    area = math.pi * ball.diameter ** 2 / 4
    h_nd = 1.225 * area * ball.diameter / (2 * ball.mass) * (
        0.40 - 0.055 - ball.mass * ball.diameter ** 2 / ball.inertia_transverse * -0.10)
    assert (d.fast_damping_rate + d.slow_damping_rate) * ball.diameter / 27.4 == pytest.approx(-h_nd, rel=1e-12)
    assert d.dynamically_stable and d.fast_damping_rate < 0 and d.slow_damping_rate < 0
    undamped = dynamic_stability(ball, 27.4, spin, AeroModel().without_extras())
    assert math.isnan(undamped.s_d) and not undamped.dynamically_stable


@pytest.mark.parametrize("aero, match", [({"c_d0": -0.1}, "outside"), ({"wind": [1, 2]}, "wind"),
                                         ({"drag": "yes"}, "true or false"), ({"colour": 1}, "unknown aero"),
                                         ({"c_m_q": 0.5}, "outside"), ({"air_density": float("nan")}, "finite")])
def test_bad_aero_settings(aero, match):
    with pytest.raises(ReleaseError, match=match):
        Release(model="full", aero=aero)


def test_aero_round_trip():
    aero = AeroModel(wind=(1.0, -2.0, 0.0), drag=False, c_l_alpha=0.3)
    assert AeroModel.from_mapping(aero.to_mapping()) == aero
    assert dataclasses.replace(aero, drag=True).drag
