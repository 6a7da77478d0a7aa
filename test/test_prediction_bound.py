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

"""The landing prediction's information limit, against closed forms and Monte Carlo."""

import math

from football_ros.estimation.bound import (
    central_jacobian,
    FD_STEPS,
    mixture_error,
    mixture_pooled_medians,
    mixture_radial_median,
    pooled_median,
    pooled_medians,
    posterior_covariance,
    radial_median,
    ThrowModel,
)
from football_ros.physics import Flight, Release
from football_ros.physics.aero import AeroModel
from football_ros.physics.frames import GRAVITY
import numpy as np
import pytest

NO_AIR = AeroModel(
    drag=False, lift=False, magnus=False, pitch_damping=False, spin_damping=False
)
"""The full model with every force off: a point mass under gravity (the axis still turns)."""
RELEASE = Release(
    model='full', speed=22.0, elevation_deg=35.0, azimuth_deg=12.0, spin_rpm=-550.0,
    alpha0_deg=1.0, beta0_deg=-0.7, position=(0.5, -0.3, 1.8),
)
NOISE = 0.02
PERIOD = 1.0 / 60.0
FIRST = 0.007
COUNT = 90  # fixes over 1.5 s


def ballistic(theta, times):
    """Closed-form point mass: positions (n, 3), landing (x, y, t) and their theta Jacobians."""
    x0, y0, z0, u, e, a = theta[:6]
    d = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    d_e = np.array([-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)])
    d_a = np.array([-math.cos(e) * math.sin(a), math.cos(e) * math.cos(a), 0.0])
    v = u * d
    t = np.asarray(times)[:, None]
    pos = np.array([x0, y0, z0]) + v * t - 0.5 * GRAVITY * t**2 * np.array([0.0, 0.0, 1.0])
    # d pos / d theta per time: (n, 3, 6)
    jac = np.zeros((t.size, 3, len(theta)))
    jac[:, :, 0:3] = np.eye(3)
    jac[:, :, 3] = t * d
    jac[:, :, 4] = t * u * d_e
    jac[:, :, 5] = t * u * d_a
    tl = (v[2] + math.sqrt(v[2] ** 2 + 2.0 * GRAVITY * z0)) / GRAVITY
    land = np.array([x0 + v[0] * tl, y0 + v[1] * tl, tl])
    # Implicit function: z(tl, theta) = 0 -> dtl = -dz/dtheta / (vz - g tl).
    dz = np.zeros(len(theta))
    dz[2] = 1.0
    dz[3:6] = tl * np.array([d[2], u * d_e[2], u * d_a[2]])
    dtl = -dz / (v[2] - GRAVITY * tl)
    jland = np.zeros((3, len(theta)))
    for i in range(2):
        jland[i, i] = 1.0
        jland[i, 3:6] = tl * np.array([d[i], u * d_e[i], u * d_a[i]])
        jland[i] += v[i] * dtl
    jland[2] = dtl
    return pos, jac, land, jland


def test_the_model_reproduces_the_flight_of_a_release():
    model = ThrowModel(FIRST, PERIOD, COUNT)
    theta = model.theta_of(RELEASE)
    out = model.evaluate(theta)
    flight = Flight.from_release(RELEASE)
    truth = np.array([flight.state_at(t)[:3] for t in model.times]).reshape(-1)
    traj = Flight.from_release(RELEASE).simulate(rate=100.0, duration=20.0)
    np.testing.assert_allclose(out[:-3], truth, atol=1e-9)
    np.testing.assert_allclose(out[-3:-1], traj.positions[-1, :2], atol=1e-9)
    assert out[-1] == pytest.approx(traj.times[-1], abs=1e-9)
    off = RELEASE.replace(aero={'c_d0': 0.055 * 1.3, 'c_d2': 0.3 * 1.3, 'c_l_alpha': 0.4 * 0.7})
    assert model.theta_of(off)[-2:] == pytest.approx([1.3, 0.7])


def test_the_wind_as_an_unknown_flies_the_release_in_its_wind():
    windy = RELEASE.replace(aero={'wind': (1.5, -5.0, 0.0)})
    model = ThrowModel(FIRST, PERIOD, COUNT, wind=True)
    theta = model.theta_of(windy)
    assert model.names[-2:] == ('wind_x', 'wind_y') and list(theta[-2:]) == [1.5, -5.0]
    traj = Flight.from_release(windy).simulate(rate=100.0, duration=20.0)
    out = model.evaluate(theta)
    np.testing.assert_allclose(out[-3:-1], traj.positions[-1, :2], atol=1e-9)
    calm = model.evaluate(np.concatenate([theta[:-2], [0.0, 0.0]]))
    assert abs(calm[-2] - out[-2]) > 1.0  # a 5 m/s crosswind moves the landing by metres


def test_finite_difference_jacobian_matches_gravity_only_motion():
    model = ThrowModel(FIRST, PERIOD, COUNT, aero=NO_AIR)
    theta = model.theta_of(RELEASE)
    f0, jac = central_jacobian(model.evaluate, theta, [FD_STEPS[n] for n in model.names])
    pos, jpos, land, jland = ballistic(theta, model.times)
    np.testing.assert_allclose(f0[:-3], pos.reshape(-1), atol=1e-9)
    np.testing.assert_allclose(f0[-3:], land, atol=1e-9)
    np.testing.assert_allclose(jac[:-3], jpos.reshape(-1, len(theta)), atol=1e-6)
    np.testing.assert_allclose(jac[-3:], jland, atol=1e-6)
    # With the air on, the spin, axis and scales do move the ball (the columns are not zero).
    _, jac_air = central_jacobian(
        ThrowModel(FIRST, PERIOD, COUNT).evaluate, theta, [FD_STEPS[n] for n in model.names]
    )
    assert np.all(np.abs(jac_air[-3:-1, 6:]).max(axis=0) > 1e-3)


def test_the_bound_of_a_linear_gaussian_throw_is_the_least_squares_covariance():
    # Fixes of a point mass with known gravity: linear in (r0, v0), so the least-squares
    # estimate is efficient and its covariance, per axis noise^2 (A'A)^-1 with A = [1, t], is
    # the bound. Compared on the predicted position 1 s after the last fix (linear in theta,
    # whatever the parametrisation) and on the landing against a Monte Carlo of the fit.
    extra = 60  # captures after the fit, the 60th is 1 s after the last fix
    model = ThrowModel(FIRST, PERIOD, COUNT + extra, aero=NO_AIR)
    theta = model.theta_of(RELEASE)
    six = [FD_STEPS[n] for n in model.names[:6]]
    _, jac = central_jacobian(
        lambda th6: model.evaluate(np.concatenate([th6, theta[6:]])), theta[:6], six
    )
    cov = posterior_covariance(jac[: 3 * COUNT], NOISE, np.zeros((6, 6)))
    k = COUNT + extra - 1
    g = jac[3 * k: 3 * k + 3]
    t = model.times[:COUNT]
    a = np.column_stack([np.ones_like(t), t])
    row = np.array([1.0, model.times[k]])
    expected = NOISE**2 * row @ np.linalg.solve(a.T @ a, row)
    np.testing.assert_allclose(g @ cov @ g.T, expected * np.eye(3), rtol=1e-6, atol=1e-12)
    # The landing: the delta-method covariance of the bound against the empirical one of the
    # least-squares fit + closed-form landing over noisy draws (3 % sampling error).
    g_land = jac[-3:-1]
    bound = g_land @ cov @ g_land.T
    pos, _, land, _ = ballistic(theta, t)
    rng = np.random.default_rng(3)
    lands = []
    for _ in range(3000):
        z = pos + rng.normal(0.0, NOISE, pos.shape)
        z[:, 2] += 0.5 * GRAVITY * t**2
        coef = np.linalg.lstsq(a, z, rcond=None)[0]
        r0, v0 = coef[0], coef[1]
        tl = (v0[2] + math.sqrt(v0[2] ** 2 + 2.0 * GRAVITY * r0[2])) / GRAVITY
        lands.append(r0[:2] + v0[:2] * tl)
    emp = np.cov(np.array(lands).T)
    np.testing.assert_allclose(np.linalg.eigvalsh(emp), np.linalg.eigvalsh(bound), rtol=0.1)
    assert radial_median(emp) == pytest.approx(radial_median(bound), rel=0.05)


def test_a_prior_alone_is_returned_and_a_parameter_without_information_is_refused():
    jac = np.array([[1.0, 0.0], [2.0, 0.0]])
    cov = posterior_covariance(jac, 0.5, np.diag([0.0, 1.0 / 0.3**2]))
    assert cov[1, 1] == pytest.approx(0.3**2)
    assert cov[0, 0] == pytest.approx(0.25 / 5.0)
    with pytest.raises(np.linalg.LinAlgError):
        posterior_covariance(jac, 0.5, np.zeros((2, 2)))


def test_radial_median_matches_closed_forms_and_sampling():
    s = 0.03
    assert radial_median(s**2 * np.eye(2)) == pytest.approx(s * math.sqrt(2 * math.log(2)))
    assert radial_median(np.diag([s**2, 0.0])) == pytest.approx(0.6744897501960817 * s)
    cov = np.array([[4e-3, 1.5e-3], [1.5e-3, 1e-3]])
    e = np.random.default_rng(0).multivariate_normal(np.zeros(2), cov, 1_000_000)
    assert radial_median(cov) == pytest.approx(np.median(np.linalg.norm(e, axis=1)), rel=3e-3)


def test_pooled_median_of_identical_flights_is_their_median():
    s = 0.05
    mean, sd = pooled_median(np.tile(s**2 * np.eye(2), (401, 1, 1)), draws=400, seed=2)
    assert mean == pytest.approx(s * math.sqrt(2 * math.log(2)), rel=0.01)
    assert 0.0 < sd < 0.1 * mean


def test_the_global_bound_of_two_modes_is_the_error_of_their_mixtures_mean():
    """
    A bimodal toy: modes 1 m apart, weights 0.8 / 0.2, each 0.1 mm wide.

    The mixture's mean lies 0.2 m from the likelier mode, so its error is 0.2 m (odds 4 in 5)
    or 0.8 m: median 0.2 m, where the likelier mode alone (the local bound) says 0.1 mm. Over
    nine such flights the pooled median is 0.8 m when five or more draw the far mode.
    """
    s, far = 1e-4, 1.0
    err = mixture_error([4.0, 1.0], [[0.0, 0.0], [far, 0.0]], [s**2 * np.eye(2)] * 2)
    np.testing.assert_allclose(err[0], [0.8, 0.2])
    np.testing.assert_allclose(err[1], [[-0.2 * far, 0.0], [0.8 * far, 0.0]], atol=1e-15)
    assert mixture_radial_median(err) == pytest.approx(0.2 * far, rel=1e-3)
    assert radial_median(s**2 * np.eye(2)) < 1e-3 * mixture_radial_median(err)
    tail = sum(math.comb(9, k) * 0.2**k * 0.8 ** (9 - k) for k in range(5, 10))
    med = mixture_pooled_medians([err] * 9, draws=20000, seed=3)
    assert med.mean() == pytest.approx(0.2 * far + 0.6 * far * tail, abs=3e-3)
    assert np.mean(med > 0.5 * far) == pytest.approx(tail, abs=0.005)


def test_the_global_bound_of_one_mode_is_the_local_bound_draw_for_draw(prediction_bound):
    """
    A spiral of the prediction benchmark (defaults: 400-800 rpm): one mode that holds weight.

    The multi-start from both hands' priors (bench/prediction_bound.py) finds the other
    hand's fit too, far out of reach; the global bound's error is then the local bound's,
    per flight and pooled (the same draws), and its one mode is the truth's own.
    """
    bench = prediction_bound
    case = bench.CASES['defaults']
    release = bench.random_releases(np.random.default_rng(1000), 1, case)[0]
    t_land, xy, obs, model = bench.flight_setup(release, 100000, 1.0, case)
    modes = bench.find_modes(release, obs, model, case)
    assert {m.hand for m in modes} == {1.0, -1.0}
    local = bench.posterior(bench.jacobians(release, model, xy),
                            bench.prior_sigmas(case, 'benchmark'), case.noise)[0]
    err = bench.global_error(modes, local)
    assert err[0].tolist() == [1.0] and np.all(err[1] == 0.0) and np.all(err[2][0] == local)
    # the truth within its mode (d2 ~ chi-square, 11 unknowns), the other hand far off
    assert modes[0].d2 < 30.0 and all(m.d2 > 1000.0 for m in modes[1:])
    assert mixture_radial_median(err) == radial_median(local)
    others = np.array([0.2**2 * np.eye(2), 0.05**2 * np.eye(2)])
    np.testing.assert_array_equal(
        mixture_pooled_medians([err] + [mixture_error([1.0], [[3.0, 4.0]], [c]) for c in others],
                               draws=500, seed=1),
        pooled_medians(np.concatenate([[local], others]), draws=500, seed=1))
