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

"""The throw planner: plans flown by Flight land where promised, least wobble, refusals."""

import math

from football_ros.physics import dynamics as dyn
from football_ros.physics import Flight, frames, Release
from football_ros.physics import linear_theory as lt
from football_ros.physics.linear_theory import linear_modes
from football_ros.planning import (
    compare_arcs,
    DEFAULT_SIGMAS,
    equilibrium_attitude,
    hit_probability,
    plan,
    PlanError,
    Receiver,
    wilson,
)
from football_ros.planning import kernels, planner
from football_ros.planning.planner import closest_approach, DEFAULT_MAX_SPEED
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as hs
import numpy as np
import pytest


def flown_miss(p, target=None):
    """Closest approach [m] of the plan's release flown by Flight (fresh, 1 ms, to landing)."""
    traj = Flight.from_release(p.release).simulate(rate=1000.0, duration=30.0)
    return closest_approach(traj.times, traj.states, p.target if target is None else target)


def random_targets(seed, n):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        rng_range = rng.uniform(5.0, 60.0)
        azim = math.radians(rng.uniform(-45.0, 45.0))
        out.append([rng_range * math.cos(azim), rng_range * math.sin(azim), rng.uniform(0, 3)])
    return out


@pytest.mark.parametrize('model', ['paper', 'full'])
def test_hidden_targets_flown_by_flight_pass_within_1cm(model):
    rng = np.random.default_rng(18)
    for i, target in enumerate(random_targets(1818 + (model == 'full'), 6)):
        aero = {}
        if model == 'full':
            wind = rng.uniform(-1.0, 1.0, 3) * np.array([1.0, 1.0, 0.2])
            aero = {'wind': list(wind / max(np.linalg.norm(wind), 1e-9) * rng.uniform(0, 10))}
        base = Release(
            ball=('american', 'rugby')[i % 2],
            spin_rpm=(1.0 if i % 3 else -1.0) * (600.0 if i % 2 == 0 else 300.0),
            position=(0.0, 0.0, 1.8),
            model=model,
            aero=aero,
        )
        p = plan(target, base, objective='fastest')
        miss, t_arr, _ = flown_miss(p, np.array(target))
        assert miss < 0.01, (target, p.release)
        assert p.miss_m < 0.01
        assert abs(t_arr - p.arrival_time) < 2e-3
        # the fastest gyroscopically stable release: max_speed unless that one tumbles
        if Flight.from_release(p.release.replace(speed=35.0)).modes.stable:
            assert p.release.speed == pytest.approx(35.0)
        else:
            assert p.release.speed < 35.0 and Flight.from_release(p.release).modes.stable


def test_planner_kernel_takes_the_real_time_kernel_steps_and_stops_past_the_plane():
    release = Release(model='full', aero={'wind': [2.0, -1.0, 0.0]}, position=(0.0, 0.0, 1.8))
    flight = Flight.from_release(release)
    ref = flight.simulate(rate=1000.0, duration=30.0)
    # The checking flight's state is the one Flight builds from the Release.
    y0 = planner._state_vector(release.initial_state(), flight.ball.inertia_ratio)
    assert np.array_equal(y0, flight.y0)
    plane, d = np.array([20.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    times, states, landed = kernels.fly(y0, 1e-3, flight.params, 30.0, 0.0, plane, d, -1)
    assert landed and ref.landed and np.array_equal(times, ref.times)
    # Positions and velocities bit for bit (propagate's samples only re-project the attitude).
    assert np.array_equal(states[:, dyn.R:dyn.V + 3], ref.states[:, dyn.R:dyn.V + 3])
    assert np.max(np.abs(states - ref.states)) < 1e-12
    short, few, landed = kernels.fly(y0, 1e-3, flight.params, 30.0, 0.0, plane, d, 2)
    first = int(np.argmax(ref.positions[:, 0] >= 20.0))
    assert not landed and len(short) == first + 3 and np.array_equal(few, states[:first + 3])
    found, t, point = kernels.plane_crossing(short, few, plane, d)
    assert found and point[0] == pytest.approx(20.0, abs=1e-9)
    assert ref.times[first - 1] < t <= ref.times[first]
    # A fixed duration ends on the last whole step at or before it, as propagate's samples.
    fixed, _, _ = kernels.fly(y0, 1e-3, flight.params, 0.4567, 0.0, plane, d, -1)
    assert len(fixed) == 457 and fixed[-1] == pytest.approx(0.456)


def test_paper_model_aim_equals_vacuum_parabola():
    # The paper's centre flies the vacuum parabola: the plan's velocity must be the ballistic one.
    base = Release(position=(0.0, 0.0, 2.0))
    p = plan([30.0, -4.0, 1.0], base, objective='flat')
    v = p.release.initial_state().velocity
    t = p.arrival_time
    expected = np.array([30.0, -4.0, 1.0 - 2.0]) / t + np.array([0.0, 0.0, 0.5 * 9.80665 * t])
    assert np.allclose(v, expected, atol=2e-3)


def test_equilibrium_release_has_no_mode_amplitudes_in_the_frozen_theory():
    base = Release()
    st = base.initial_state()
    params = dyn.make_params(base.preset())
    h1 = base.preset().inertia_ratio * st.spin
    att = equilibrium_attitude(params, st.velocity, h1, drift=False)
    modes = linear_modes(base.preset(), base.replace(**att).initial_state())
    s3p = modes.equilibrium_sideslip
    assert math.degrees(s3p) == pytest.approx(3.534, abs=1e-3)
    assert abs(modes.c1) < 1e-9 and abs(modes.c2) < 1e-9
    assert att['beta0_deg'] == pytest.approx(math.degrees(math.asin(s3p)), abs=1e-9)
    assert att['alpha0_deg'] == pytest.approx(0.0, abs=1e-9)
    # The axis turns with the velocity frame: w_V = -g cos(Phi) / V.
    assert att['alpha_rate_deg_s'] == pytest.approx(math.degrees(modes.omega_v), rel=1e-6)
    # With the equilibrium's drift: nose h1 s3p' / M_alpha above it (docs/physics.md).
    drift = equilibrium_attitude(params, st.velocity, h1)
    assert 0.2 < drift['alpha0_deg'] < 1.0
    assert drift['beta0_deg'] == pytest.approx(att['beta0_deg'], rel=0.03)


@pytest.mark.parametrize('model', ['paper', 'full'])
def test_compiled_equilibrium_axes_are_the_linear_theory_ones(model):
    # kernels.equilibrium_axes (the linear theory's plain-float functions, compiled) against
    # the vectorised path (local_exponents, drifting_equilibrium, frames) on a windy flight.
    aero = {'wind': [3.0, -2.0, 0.5]} if model == 'full' else {}
    release = Release(model=model, aero=aero, position=(0.0, 0.0, 1.8), beta0_deg=2.0)
    flight = Flight.from_release(release)
    states = flight.simulate(rate=200.0, duration=2.5).states
    params = flight.params
    axis, eq = kernels.equilibrium_axes(states, params, lt.scalar_constants(params))
    air = states[:, dyn.V:dyn.V + 3] - params[dyn.P_WIND:dyn.P_WIND + 3]
    h1 = states[:, dyn.H1]
    _, _, b, d_c, x_p = lt.local_exponents(params, air, h1)
    x_eq = lt.drifting_equilibrium(lambda a, h: lt.local_exponents(params, a, h),
                                   lt.scalar_constants(params), air, h1, b, d_c, x_p)[0]
    s1 = np.sqrt(1.0 - np.abs(x_eq) ** 2)
    ref = frames.from_velocity_frame(np.stack([s1, x_eq.real, x_eq.imag], axis=-1), air)
    ref /= np.linalg.norm(ref, axis=-1, keepdims=True)
    assert np.max(np.abs(eq - ref)) < 1e-12
    assert np.array_equal(axis, dyn.describe(states, params)[:, dyn.D_AXIS:dyn.D_AXIS + 3])
    # The equilibrium is a few degrees off the air velocity, as the linear theory says.
    off = np.degrees(np.arccos(np.sum(ref * air / np.linalg.norm(air, axis=-1)[:, None], -1)))
    assert 1.0 < np.median(off) < 10.0
    # The wobble kernel: the largest axis-equilibrium angle over the rows, delta at the last.
    rows = np.arange(0, len(states), 3)
    largest, delta = kernels.wobble(states, rows, params, lt.scalar_constants(params))
    angles = np.arccos(np.clip(np.sum(axis * ref, axis=-1), -1.0, 1.0))[rows]
    assert largest == pytest.approx(np.max(angles), abs=1e-11)
    assert delta == dyn.describe(states[rows[-1:]], params)[0, dyn.D_DELTA]
    assert 0.5 < math.degrees(largest) < 20.0


@pytest.mark.parametrize('model', ['paper', 'full'])
def test_nominal_pass_wobble_at_most_a_tenth_of_aligned(model):
    nominal = Release(model=model)
    landing = Flight.from_release(nominal).simulate(rate=100.0, duration=10.0).positions[-1]
    p = plan(landing, Release(model=model), objective='flat')
    assert p.release.elevation_deg == pytest.approx(30.0, abs=0.5)
    assert p.miss_m < 0.01
    assert p.aligned_wobble_deg > 3.0  # the slow mode, about s3p w_f / (w_f - w_s)
    assert 'right' in p.sentence and 'turning with it' in p.sentence
    linear = plan(landing, Release(model=model), objective='flat', attitude='linear')
    assert linear.release.beta0_deg == pytest.approx(p.linear_release['beta0_deg'], abs=0.05)
    # The analytic releases: a fifth of the aligned wobble or less (with or without the drift).
    assert max(p.wobble_deg, linear.wobble_deg) < 0.2 * p.aligned_wobble_deg
    refined = plan(landing, Release(model=model), objective='flat', attitude='refined')
    # The target (<= 0.1 x aligned) holds for the paper's model; the full model's floor
    # (0.45 of 3.57 deg: the best any release attitude reaches, bench/planner_benchmark.py's
    # floor row) is the quasi-steady reference's own error there, not a wobble an attitude
    # could remove.
    ratio = 0.1 if model == 'paper' else 0.13
    assert refined.wobble_deg <= ratio * refined.aligned_wobble_deg
    assert refined.wobble_deg < min(p.wobble_deg, linear.wobble_deg)
    assert flown_miss(refined)[0] < 0.01


def _aligned_by_flight(p):
    """Fly the plan's aligned release in the simulator's own steps to the last checked row."""
    base = p.release
    sh = planner._Shooter(base, planner.DEFAULT_STEP)
    sh.aim(p.target)
    y_check = planner._state_vector(base.initial_state(), sh.ball.inertia_ratio)
    times, states, _ = kernels.fly(y_check, sh.step, sh.params, 30.0, 0.0, sh.target, sh.d,
                                   planner.PAST_PLANE_STEPS)
    n = int(np.searchsorted(times, p.arrival_time + 1e-12, 'right'))
    sh.mode = 'aligned'
    y0 = sh.y0(base.speed, base.elevation_deg, base.azimuth_deg, float(y_check[dyn.H1]))
    a_times, a_states, _ = kernels.fly(y0, sh.step, sh.params, times[n - 1], 0.0, sh.target,
                                       sh.d, -1)
    return (planner.wobble_of(times[:n], states[:n], sh.params),
            planner.wobble_of(a_times, a_states, sh.params))


@pytest.mark.parametrize('model', ['paper', 'full'])
def test_aligned_comparison_in_its_coarser_steps_agrees_with_the_simulators(model):
    # The aligned release flies in steps of ALIGNED_STEP (2.5 ms): its wobble and delta at
    # the arrival within 1e-3 deg (the plan's printed digits) of the same release in the
    # simulator's 1 ms steps, at spins up to 900 rpm; the
    # planned release's own numbers are those of its checking flight, exactly.
    rng = np.random.default_rng(2318 + (model == 'full'))
    for i, target in enumerate(random_targets(2319 + (model == 'full'), 8)):
        base = Release(model=model, ball='rugby' if i % 3 == 2 else 'american',
                       spin_rpm=float(rng.choice([-1.0, 1.0]) * rng.uniform(300.0, 900.0)),
                       position=(0.0, 0.0, 1.8))
        p = plan(target, base, max_speed=35.0)
        (wob, delta), (a_wob, a_delta) = _aligned_by_flight(p)
        assert (p.wobble_deg, p.arrival_delta_deg) == (wob, delta)
        assert p.aligned_wobble_deg == pytest.approx(a_wob, abs=1e-3)
        assert p.aligned_arrival_delta_deg == pytest.approx(a_delta, abs=1e-3)
        assert p.aligned_wobble_deg > 0.5  # a real comparison, not two zeros


def test_minimax_of_the_refinement():
    # Residuals on a circle of radius 0.3 around c: the offsets -c leave 0.3 everywhere.
    angles = np.linspace(0.0, 2.0 * math.pi, 90, endpoint=False)
    c = np.array([0.5, -0.2, 0.0])
    d0 = c + 0.3 * np.stack([np.cos(angles), np.sin(angles), 0.0 * angles], axis=-1)
    jac = np.broadcast_to(np.eye(3)[:, :2], (90, 3, 2))
    x = planner._minimax(d0, jac)
    assert np.allclose(x, -c[:2], atol=1e-6)
    worst = np.max(np.linalg.norm(d0 + jac @ x, axis=-1))
    assert worst == pytest.approx(0.3, abs=1e-6)


def test_objectives_and_arcs():
    base = Release(position=(0.0, 0.0, 1.8))
    target = [35.0, 3.0, 1.5]
    flat = plan(target, base, objective='flat')
    lofted = plan(target, base, objective='lofted')
    low = plan(target, base, objective='lowest_speed')
    fast = plan(target, base, objective='fastest')
    for p in (flat, lofted, low, fast):
        assert flown_miss(p)[0] < 0.01
    assert flat.release.elevation_deg < low.release.elevation_deg < lofted.release.elevation_deg
    assert low.release.speed < flat.release.speed == pytest.approx(27.4)
    # Vacuum least speed: V^2 = g (h + sqrt(h^2 + R^2)).
    r, h = math.hypot(35.0, 3.0), -0.3
    assert low.release.speed == pytest.approx(math.sqrt(9.80665 * (h + math.hypot(h, r))), 1e-3)
    assert fast.arrival_time < flat.arrival_time < lofted.arrival_time


def test_arrival_time_and_window():
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    p = plan([25.0, 0.0, 1.5], base, arrival_time=1.7)
    assert p.arrival_time == pytest.approx(1.7, abs=2e-3)
    assert flown_miss(p)[0] < 0.01
    w = plan([25.0, 0.0, 1.5], base, objective='fastest', arrival_window=(1.2, 2.0))
    assert w.arrival_time == pytest.approx(1.2, abs=2e-3)


def test_moving_receiver_intercepted():
    rx = Receiver(position=(30.0, -5.0, 1.2), velocity=(2.0, 4.0, 0.0), time=0.0)
    base = Release(position=(0.0, 0.0, 1.8), model='full', aero={'wind': [3.0, -2.0, 0.0]})
    p = plan(receiver=rx, base=base, objective='flat')
    traj = Flight.from_release(p.release).simulate(rate=1000.0, duration=30.0)
    # Ball and receiver at the same place at the same time.
    t = p.arrival_time
    k = int(round(t * 1000.0))
    gap = np.linalg.norm(traj.positions[k] - rx.at(traj.times[k]))
    assert gap < 0.01 + 0.03  # sample within half a step of the arrival (ball ~25 m/s)
    assert np.linalg.norm(p.arrival_point - rx.at(t)) < 0.01
    assert np.linalg.norm(rx.at(t) - np.array(rx.position)) > 4.0  # it did move


def test_infeasible_targets_name_the_limit_and_the_closest_point():
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    with pytest.raises(PlanError, match='max_speed') as info:
        plan([150.0, 0.0, 1.0], base, objective='fastest', max_speed=25.0)
    assert info.value.limit == 'max_speed'
    closest = info.value.closest
    assert closest is not None and 40.0 < closest[0] < 80.0  # reachable, short of 150 m
    with pytest.raises(PlanError, match='below the ground'):
        plan([20.0, 0.0, -1.0], base)
    with pytest.raises(PlanError, match='finite'):
        plan([20.0, float('nan'), 1.0], base)
    with pytest.raises(PlanError, match='finite'):
        plan([float('inf'), 0.0, 1.0], base)
    with pytest.raises(PlanError, match='3 numbers'):
        plan([1.0, 2.0], base)
    with pytest.raises(PlanError, match='3 numbers'):
        plan('x', base)
    with pytest.raises(PlanError, match='objective'):
        plan([20.0, 0.0, 1.0], base, objective='hardest')
    with pytest.raises(PlanError, match='max_speed'):
        plan([20.0, 0.0, 1.0], base, max_speed=float('nan'))
    with pytest.raises(PlanError, match='horizontally'):
        plan([0.1, 0.0, 5.0], base)
    with pytest.raises(PlanError, match='elevation'):
        plan([20.0, 0.0, 1.0], base, objective='lofted', elevation_range=(0.0, 20.0))
    with pytest.raises(PlanError, match='exactly one'):
        plan(None, base)
    with pytest.raises(PlanError, match='receiver.velocity'):
        plan(receiver=Receiver((20.0, 0.0, 1.0), (float('nan'), 0.0, 0.0)), base=base)


def test_wilson_interval():
    lo, hi = wilson(50, 100)
    assert lo == pytest.approx(0.4038, abs=1e-4) and hi == pytest.approx(0.5962, abs=1e-4)
    lo, hi = wilson(0, 20)
    assert lo == 0.0 and hi == pytest.approx(0.1611, abs=1e-4)


def test_hit_probability_from_the_batch_kernel():
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    p = plan([30.0, 2.0, 1.0], base, objective='flat')
    sure = hit_probability(p, dict.fromkeys(DEFAULT_SIGMAS, 0.0), catch_radius=0.01, n=64)
    assert sure.probability == 1.0  # the batch kernel flies the plan within 1 cm too
    est = hit_probability(p, catch_radius=0.5, n=2000, seed=1)
    assert 0.0 < est.probability < 1.0
    assert est.low < est.probability < est.high
    wide = hit_probability(p, catch_radius=5.0, n=2000, seed=1)
    assert wide.probability > est.probability
    with pytest.raises(PlanError, match='sigma'):
        hit_probability(p, {'speed': -1.0})
    with pytest.raises(PlanError, match='catch_radius'):
        hit_probability(p, catch_radius=float('nan'))


def test_compare_arcs_names_the_more_robust_one():
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    out = compare_arcs([40.0, 0.0, 0.5], base, n=3000, seed=2)
    (flat, f_est), (lofted, l_est) = out['flat'], out['lofted']
    assert flat.release.elevation_deg < lofted.release.elevation_deg
    assert flat.arrival_time < lofted.arrival_time
    if f_est.low > l_est.high:
        assert out['more_robust'] == 'flat'
    elif l_est.low > f_est.high:
        assert out['more_robust'] == 'lofted'
    else:
        assert out['more_robust'] == 'either'
    # Out of reach for the lofted arc within 30 deg: the flat one only.
    only = compare_arcs([40.0, 0.0, 0.5], base, n=200, elevation_range=(-45.0, 30.0))
    assert isinstance(only['lofted'], PlanError) and only['more_robust'] == 'flat'


NUMBER = hs.floats(allow_nan=True, allow_infinity=True) | hs.floats(-100.0, 100.0)


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    target=hs.lists(NUMBER, min_size=3, max_size=3)
    | hs.tuples(hs.floats(-5.0, 70.0), hs.floats(-30.0, 30.0), hs.floats(-1.0, 5.0)).map(list),
    objective=hs.sampled_from(['fastest', 'lowest_speed', 'flat', 'lofted']),
    max_speed=hs.floats(0.0, 80.0) | hs.floats(15.0, 40.0),
    elevation=hs.tuples(hs.floats(-90.0, 90.0), hs.floats(-90.0, 90.0))
    | hs.tuples(hs.floats(-45.0, 10.0), hs.floats(30.0, 80.0)),
    arrival=hs.none() | hs.none() | hs.floats(-1.0, 40.0),
    model=hs.sampled_from(['paper', 'full']),
)
def test_plan_answers_a_checked_plan_or_a_plan_error(target, objective, max_speed, elevation,
                                                     arrival, model):
    base = Release(position=(0.0, 0.0, 1.5), model=model)
    try:
        p = plan(target, base, objective=objective, max_speed=max_speed,
                 elevation_range=elevation, arrival_time=arrival)
    except PlanError as exc:
        assert str(exc)
        return
    assert p.miss_m <= 0.01 and math.isfinite(p.arrival_time)
    assert p.release.speed <= max_speed + 1e-9
    assert elevation[0] - 1e-9 <= p.release.elevation_deg <= elevation[1] + 1e-9


def test_hard_cases_a_headwind_lofted_arc_a_slow_throw_and_a_steep_one():
    wind = {'wind': [-5.77, -3.67, 0.0]}
    base = Release(ball='rugby', spin_rpm=300.0, position=(0.0, 0.0, 1.8), model='full',
                   aero=wind)
    # The vacuum guess (67 deg) is blown back before the target: the planner walks down.
    lofted = plan([28.53, 1.06, 2.62], base, objective='lofted')
    assert 55.0 < lofted.release.elevation_deg < 67.0 and flown_miss(lofted)[0] < 0.01
    # A 9 m/s lob: its equilibrium sideslip (~ 1/V^3) is far beyond the linear theory, so the
    # axis goes along the air velocity, turning with it, and the plan says so.
    slow = plan([7.0, 0.2, 1.4], base, objective='lowest_speed')
    assert slow.release.speed < 12.0 and flown_miss(slow)[0] < 0.01
    assert any('beyond the linear theory' in w or 'aligned release wobbles less' in w
               for w in slow.warnings)
    # The lofted arc at 20 m/s to 8 m needs about 84 deg: the elevation limit is named.
    with pytest.raises(PlanError, match='elevation_range') as info:
        plan([8.3, -1.2, 2.3], base, objective='lofted')
    assert info.value.limit == 'elevation_range'


# --- the plan is never worse than the aligned release; refusals name their own limit ---------
def _random_plans(seed: int, n: int):
    """Yield n random (target, base, objective): both balls, slow lobs to long passes."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        ball = str(rng.choice(['american', 'rugby']))
        spin = float(rng.uniform(250.0, 700.0)) * float(rng.choice([-1.0, 1.0]))
        base = Release(ball=ball, spin_rpm=spin, position=(0.0, 0.0, 1.8), model='full',
                       speed=float(rng.uniform(12.0, 25.0)))
        target = [float(rng.uniform(6.0, 40.0)), float(rng.uniform(-5.0, 5.0)),
                  float(rng.uniform(0.5, 3.0))]
        yield target, base, str(rng.choice(['fastest', 'lowest_speed', 'flat', 'lofted']))


def test_random_plans_never_wobble_more_than_the_aligned_release():
    planned = 0
    for target, base, objective in _random_plans(37, 12):
        try:
            p = plan(target, base, objective=objective)
        except PlanError as exc:
            assert exc.limit  # refused with its limit named
            continue
        planned += 1
        assert p.wobble_deg <= p.aligned_wobble_deg + 1e-9
        if p.attitude == 'aligned':
            assert any('aligned release wobbles less' in w for w in p.warnings)
        assert flown_miss(p)[0] < 0.01
        if p.objective == 'fastest':  # the fastest plan is gyroscopically stable
            modes = Flight.from_release(p.release).modes
            assert modes.stable and p.release.speed <= DEFAULT_MAX_SPEED + 1e-9
    assert planned >= 6


def test_fastest_is_the_fastest_gyroscopically_stable_release_or_refused():
    base = Release(ball='rugby', spin_rpm=300.0, position=(0.0, 0.0, 1.8), model='full')
    p = plan([25.0, 0.0, 1.5], base, objective='fastest')
    modes = Flight.from_release(p.release).modes
    assert modes.stable and modes.gyroscopic_stability_factor == pytest.approx(1.0, abs=0.01)
    assert p.release.speed < DEFAULT_MAX_SPEED
    faster = Flight.from_release(p.release.replace(speed=p.release.speed * 1.01)).modes
    assert not faster.stable  # 1 % faster tumbles: it is the fastest stable one
    with pytest.raises(PlanError, match='fastest gyroscopically stable') as info:
        plan([60.0, 0.0, 1.5], Release(ball='rugby', spin_rpm=150.0, model='full'),
             objective='fastest')
    assert info.value.limit == 'gyroscopic_stability'


def test_plans_leaving_the_data_range_warn_as_simulate_does():
    from football_ros.cli import simulate_warnings

    base = Release(ball='rugby', spin_rpm=-280.0, position=(0.0, 0.0, 1.8), model='full')
    p = plan([30.0, 0.0, 1.0], base, objective='lofted')
    flight = Flight.from_release(p.release)
    flown = flight.simulate(rate=100.0, duration=p.arrival_time)
    expected = simulate_warnings(p.release, flight, flown)
    assert expected and all(w in p.warnings for w in expected)


def test_refusals_spin_zero_arrival_time_plain_numbers_and_the_envelope():
    base = Release(position=(0.0, 0.0, 1.8), model='full')
    with pytest.raises(PlanError, match='spin_rpm is 0') as info:
        plan([20.0, 0.0, 1.5], base.replace(spin_rpm=0.0))
    assert info.value.limit == 'spin_rpm'
    with pytest.raises(PlanError, match='arrives at the target 0.1 s after release') as info:
        plan([20.0, 0.0, 1.5], base, arrival_time=0.1)
    assert info.value.limit == 'arrival_time' and 'takes about' in str(info.value)
    with pytest.raises(PlanError) as info:
        plan([20.0, float('nan'), 1.0], base)
    assert str(info.value) == "'target' must be finite, got [20, nan, 1]"
    # Out of reach: the closest point is the envelope's (the best of all elevations at
    # max_speed, here against a fine scan of 800), not a coarse scan's.
    target = np.array([30.0, 0.0, 60.0])
    with pytest.raises(PlanError) as info:
        plan(target, base)
    got = np.linalg.norm(info.value.closest - target)
    best = math.inf
    for elev in np.linspace(0.0, 80.0, 800):
        tr = Flight.from_release(base.replace(speed=DEFAULT_MAX_SPEED, elevation_deg=elev)
                                 ).simulate(rate=1000.0, duration=10.0)
        best = min(best, float(np.min(np.linalg.norm(tr.positions - target, axis=1))))
    assert got <= best + 0.02
