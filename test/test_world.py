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

"""The simulator's ROS-free world: flight runs, guard, entities, lock-step (no ROS imported)."""

import dataclasses
import subprocess
import sys

from football_ros.physics import Flight, Release
from football_ros.simulation import world as wd
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

UPRIGHT = np.array([0.0, 0.0, 0.0, 1.0])


def run_of(release: Release, label: str = 'r') -> wd.FlightRun:
    return wd.FlightRun(label, Flight.from_release(release))


def sample_at(world: wd.World, entities, times) -> list:
    """Return the entities' samples at flight times [s] (landed ones: their landing)."""
    flying = [e for e in entities if e.condition == 'flying']
    rows = np.array([e.slot for e in flying], dtype=np.int64)
    t = np.array([tk for e, tk in zip(entities, times) if e.condition == 'flying'])
    world.commit(world.compute(rows, t), 0)
    return [world.sample_of(e) for e in entities]


def test_no_ros_imported():
    code = (
        'import sys, football_ros.simulation.world; '
        "print([m for m in sys.modules if m.split('.')[0] in ('rclpy', 'rcl_interfaces')])"
    )
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == '[]'


def test_guard_reasons():
    run = run_of(Release(), 'guard')
    good = run.flight.sample(1.0)
    assert run.runaway(good) is None
    nan = dataclasses.replace(good, axis=np.array([np.nan, 0.0, 0.0]))
    assert 'non-finite' in run.runaway(nan)
    # 27.4 m/s from 0 m: the release allows 27.4 m/s; 10 x that is a runaway.
    fast = dataclasses.replace(good, velocity=np.array([275.0, 0.0, 0.0]))
    assert 'runaway: speed 275' in run.runaway(fast)
    spinning = dataclasses.replace(good, angular_velocity=np.array([1e5, 0.0, 0.0]))
    assert 'angular rate' in run.runaway(spinning)
    far = dataclasses.replace(good, position=np.array([2e5, 0.0, 1.0]))
    assert 'from the release point' in run.runaway(far)
    late = dataclasses.replace(good, t=wd.MAX_FLIGHT_S + 1.0)
    assert 'no landing' in run.runaway(late)
    assert run.end('because') == "flight 'guard' ended: because"
    assert run.end('again') is None


def test_ticks_show_each_time_then_the_landing_once_then_hold():
    world = wd.World()
    run = run_of(Release())
    world.throw(world.default, run)
    shown = [world.fly(0.01, 0) for _ in range(3)]
    assert [s.tolist() for s in shown] == [[0]] * 3
    assert world.flown[0] == 0.02 and world.next_t[0] == pytest.approx(0.03)
    release = Release()
    vz = release.speed * np.sin(np.radians(release.elevation_deg))
    while world.default.condition == 'flying':
        world.fly(0.05, 5_000_000_000)
    assert run.time == pytest.approx(2 * vz / 9.81, rel=1e-3)  # a parabola's time of flight
    landed = [text for _level, event, text, _label in world.events if event == 'landed']
    assert len(landed) == 1 and landed[0].startswith("flight 'r' landed at x = ")
    assert world.fly(0.05, 6_000_000_000).size == 0  # landed: not flown again
    # Landed: held once per 1 / hold_rate of wall time.
    assert world.due(5_500_000_000, 1.0).size == 0
    assert world.due(6_000_000_000, 1.0).tolist() == [0]
    assert world.due(6_000_000_001, 0.0).size == 0


def test_validity_warned_once():
    world = wd.World()
    world.throw(world.default, run_of(Release(alpha0_deg=40.0)))
    world.fly(0.01, 0)
    world.fly(0.01, 0)
    texts = [text for _level, event, text, _label in world.events if event == 'validity']
    assert len(texts) == 1 and 'left the data range' in texts[0]


def test_spawn_names_limits_and_delete():
    world = wd.World(max_entities=3)
    assert list(world.entities) == [wd.DEFAULT_ENTITY]
    a = world.spawn('a', 'football_ros://rugby', [1.0, 2.0, 0.0], UPRIGHT)
    assert a.uri == 'football_ros://rugby' and a.condition == 'at rest'
    position, orientation, velocity, omega = a.state()
    assert position.tolist() == [1.0, 2.0, 0.0] and not velocity.any() and not omega.any()
    refusals = [
        (('a', 'football_ros://american'), 'name_not_unique'),
        (('', 'football_ros://american'), 'name_invalid'),
        (('9lives', 'football_ros://american'), 'name_invalid'),
        (('x/y', 'football_ros://american'), 'name_invalid'),
        (('b' * 64, 'football_ros://american'), 'name_invalid'),
        (('b', ''), 'no_resource'),
        (('b', 'model://ball.sdf'), 'unsupported_format'),
        (('b', 'football_ros://soccer'), 'not_found'),
    ]
    for (name, uri), reason in refusals:
        with pytest.raises(wd.EntityError) as info:
            world.spawn(name, uri, [0.0, 0.0, 0.0], UPRIGHT)
        assert info.value.reason == reason, (name, uri, str(info.value))
    renamed = world.spawn('a', 'football_ros://american', [0, 0, 0], UPRIGHT, True)
    assert renamed.name != 'a' and wd.NAME_PATTERN.fullmatch(renamed.name)
    with pytest.raises(wd.EntityError) as info:
        world.spawn('c', 'football_ros://american', [0, 0, 0], UPRIGHT)
    assert info.value.reason == 'limit' and 'limit of 3' in str(info.value)
    with pytest.raises(wd.EntityError) as info:
        world.delete(wd.DEFAULT_ENTITY)
    assert info.value.reason == 'default'
    with pytest.raises(wd.EntityError) as info:
        world.delete('nobody')
    assert info.value.reason == 'not_found'
    world.delete('a')
    assert list(world.entities) == [wd.DEFAULT_ENTITY, renamed.name]


@pytest.mark.parametrize(
    'position, orientation, words',
    [
        ([np.nan, 0.0, 0.0], UPRIGHT, 'finite'),
        ([0.0, 0.0, -1.0], UPRIGHT, 'outside the field'),
        ([1e9, 0.0, 0.0], UPRIGHT, 'outside the field'),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], 'unit quaternion'),
        ([0.0, 0.0, 0.0], [np.inf, 0.0, 0.0, 1.0], 'finite'),
        ([0.0, 0.0], UPRIGHT, 'position must be 3'),
    ],
)
def test_bad_poses(position, orientation, words):
    with pytest.raises(wd.EntityError) as info:
        wd.check_pose(position, orientation)
    assert info.value.reason == 'pose' and words in str(info.value)


def test_select_filters():
    world = wd.World()
    world.spawn('near', 'football_ros://american', [1.0, 0.0, 0.0], UPRIGHT)
    world.spawn('far', 'football_ros://rugby', [50.0, 0.0, 0.0], UPRIGHT)
    names = [e.name for e in world.select()]
    assert names == ['football', 'near', 'far']
    assert [e.name for e in world.select('^f')] == ['football', 'far']
    assert [e.name for e in world.select(tags=('rugby',))] == ['far']
    assert [e.name for e in world.select(tags=('rugby', 'american'), all_tags=True)] == []
    assert [e.name for e in world.select(sphere=(np.zeros(3), 1.0))] == ['football', 'near']
    box = (np.array([40.0, -1.0, -1.0]), np.array([60.0, 1.0, 1.0]))
    assert [e.name for e in world.select(box=box)] == ['far']
    for bad in ('(', '(?=x)', '\\1', 'x' * 300):
        with pytest.raises(wd.EntityError) as info:
            world.select(bad)
        assert info.value.reason == 'filter'


def test_lock_step_equals_offline_flight_and_repeats_bit_for_bit():
    def play():
        world = wd.World()
        releases = [Release(), Release(ball='rugby', spin_rpm=-300.0), Release(speed=15.0)]
        for k, release in enumerate(releases):
            entity = world.spawn(f'b{k}', f'football_ros://{release.ball}', [0, 0, 0], UPRIGHT)
            world.throw(entity, run_of(release, entity.name))
        out = []
        for n in (1, 999, 500, 2000):
            out.append([(e.name, s.t, s.position.copy()) for e, s in world.step(n, 0.001, 0)])
        return world, releases, out

    world, releases, first = play()
    _, _, second = play()
    for x, y in zip(first, second, strict=True):  # identical calls, identical bits
        for (n1, t1, p1), (n2, t2, p2) in zip(x, y, strict=True):
            assert n1 == n2 and t1 == t2 and np.array_equal(p1, p2)
    # Against the offline Flight at the same times (1 + 999 + 500 + 2000 steps of 1 ms).
    offline = [Flight.from_release(r) for r in releases]
    for k, steps in enumerate((1, 1000, 1500, 3500)):
        for (name, t, position), flight in zip(first[k], offline):
            expected = flight.sample(steps * 0.001)
            if expected.landed:
                assert t == pytest.approx(expected.t, abs=1e-12)
            np.testing.assert_allclose(position, expected.position, rtol=0, atol=1e-9)
    # Every ball has landed by 3.5 s (the 15 m/s pass first, after 2 vz / g) and said so once.
    landed = [text for _level, event, text, _label in world.events if event == 'landed']
    assert sorted(text.split("'")[1] for text in landed) == ['b0', 'b1', 'b2']
    assert world.entities['b2'].last.t == pytest.approx(2 * 7.5 / 9.81, rel=1e-3)
    assert world.entities['b2'].condition == 'landed'
    assert not world.entities['b2'].state()[2].any()  # at rest: no velocity


def test_reset_scopes():
    world = wd.World()
    entity = world.spawn('a', 'football_ros://american', [3.0, 0.0, 1.0], UPRIGHT)
    world.throw(entity, run_of(Release()))
    world.step(100, 0.001, 0)
    world.place(world.default, [5.0, 5.0, 1.0], UPRIGHT)
    world.reset(state=True, spawned=False)
    assert entity.run is None and entity.state()[0].tolist() == [3.0, 0.0, 1.0]
    assert world.default.state()[0].tolist() == [0.0, 0.0, 0.0]
    world.reset(state=False, spawned=True)
    assert list(world.entities) == [wd.DEFAULT_ENTITY]


@settings(max_examples=200, deadline=None)
@given(
    name=st.text(max_size=80),
    uri=st.text(max_size=40) | st.sampled_from(['football_ros://american']),
    pose=st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=7, max_size=7),
    rename=st.booleans(),
    pattern=st.text(max_size=20),
)
def test_fuzz_spawn_and_select(name, uri, pose, rename, pattern):
    world = wd.World(max_entities=2)
    try:
        entity = world.spawn(name, uri, pose[:3], pose[3:], rename)
    except wd.EntityError as exc:
        assert exc.reason in (
            'name_invalid',
            'name_not_unique',
            'no_resource',
            'unsupported_format',
            'not_found',
            'pose',
            'limit',
        )
    else:
        assert wd.NAME_PATTERN.fullmatch(entity.name)
        assert np.isfinite(np.concatenate(entity.state())).all()
    try:
        world.select(pattern)
    except wd.EntityError as exc:
        assert exc.reason == 'filter'


@pytest.mark.parametrize('release', [Release(), Release(ball='rugby', spin_rpm=-300.0)])
def test_kernel_equals_flight_at_any_time_and_landing(release):
    world = wd.World()
    entity = world.spawn('k', f'football_ros://{release.ball}', [0, 0, 0], UPRIGHT)
    run = run_of(release, 'k')
    world.throw(entity, run)
    offline = Flight.from_release(release)
    for t in np.arange(0.0, 5.0, 0.0137):  # partial steps, then past the landing
        (got,) = sample_at(world, [entity], [float(t)])
        want = offline.sample(float(t))
        assert got.landed == want.landed and got.t == pytest.approx(want.t, abs=1e-12)
        for a, b in (
            (got.position, want.position),
            (got.velocity, want.velocity),
            (got.orientation, want.orientation),
            (got.angular_velocity, want.angular_velocity),
        ):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    assert got.landed and got.position[2] == 0.0


def test_batch_guard_clears_fine_balls_and_ends_a_broken_one():
    from football_ros.physics import dynamics as dyn

    world = wd.World()
    a = world.spawn('a', 'football_ros://american', [0, 0, 0], UPRIGHT)
    b = world.spawn('b', 'football_ros://american', [0, 0, 0], UPRIGHT)
    for entity in (a, b):
        world.throw(entity, run_of(Release(), entity.name))
    world.step(10, 0.001, 0)
    assert world.compute(world.flying(), world.next_t[world.flying()]).fine.all()
    world.y[b.slot, 3] = np.nan  # a broken state (the velocity)
    out = world.step(10, 0.001, 0)
    assert [e.name for e, _s in out] == ['a']
    assert b.run.ended and 'non-finite' in b.run.ended
    errors = [text for _level, event, text, _label in world.events if event == 'error']
    assert errors == [f"flight 'b' ended: {b.run.ended}"]
    # Finite but past a bound: the compiled guard (kernel.runaway_free) defers to runaway(),
    # which words the reason; the good ball stays cleared by the compiled guard.
    for index, value, reason in ((dyn.R, 2e5, 'from the release point'),
                                 (dyn.V, 300.0, 'runaway: speed'),
                                 (dyn.H, 5e3, 'runaway: angular rate')):
        world.throw(b, run_of(Release(), 'b'))
        world.y[b.slot, index] = value
        rows = world.flying()
        assert world.compute(rows, world.next_t[rows]).fine.tolist() == [True, False]
        out = world.step(1, 0.001, 0)
        assert reason in b.run.ended and [e.name for e, _s in out] == ['a']
        assert b.condition == 'ended'


def _exact(sample, flight: Flight, t: float) -> bool:
    """Tell whether the world's sample is bit for bit Flight.state_at(t) and its describe()."""
    from football_ros.physics import dynamics as dyn

    state = flight.state_at(t)
    d = dyn.describe(state[None, :], flight.params)[0]
    landed = flight.landing_time is not None
    return (
        sample.landed == landed
        and sample.t == (flight.landing_time if landed else t)
        and np.array_equal(sample.position, state[dyn.R:dyn.R + 3])
        and np.array_equal(sample.velocity, state[dyn.V:dyn.V + 3])
        and np.array_equal(sample.orientation, d[dyn.D_ORIENT:dyn.D_ORIENT + 4])
        and np.array_equal(sample.angular_velocity, d[dyn.D_OMEGA:dyn.D_OMEGA + 3])
    )


def test_lanes_bit_for_bit_flight_with_groups_singles_and_landings_mid_call():
    from football_ros.simulation import kernel

    # 20 lobs with equal parameters (more than one set of lanes, balls taking freed lanes),
    # three of them released at other heights and speeds (landing at other steps, mid-call);
    # a group of MIN_LANED full-model rugby balls; two single balls (one by one).
    lob = Release(speed=25.0, elevation_deg=60.0)
    releases = [lob] * 17 + [
        Release(speed=25.0, elevation_deg=60.0, position=(0.0, 0.0, h)) for h in (0.5, 3.0, 9.0)
    ]
    releases += [Release(model='full', ball='rugby', spin_rpm=-250.0)] * kernel.MIN_LANED
    releases += [Release(speed=15.0), Release(ball='rugby', spin_rpm=-300.0)]
    world = wd.World(max_entities=len(releases) + 1)
    runs, offline, entities = [], [], []
    for k, release in enumerate(releases):
        entity = world.spawn(f'b{k}', f'football_ros://{release.ball}', [0, 0, 0], UPRIGHT)
        run = run_of(release, entity.name)
        world.throw(entity, run)
        runs.append(run)
        entities.append(entity)
        offline.append(Flight.from_release(release))
    # Different times per ball in one call (partial steps), through every landing.
    for t in np.arange(0.0, 6.0, 0.0937):
        times = [float(t) + 0.00037 * k for k in range(len(runs))]
        samples = sample_at(world, entities, times)
        for sample, flight, tk in zip(samples, offline, times, strict=True):
            assert _exact(sample, flight, tk)
    assert all(run.landing is not None for run in runs)
    assert len({flight.landing_time for flight in offline}) > 5  # lands at many steps


def test_lock_step_lanes_bit_for_bit_and_a_broken_lane_alone():
    lob = Release(speed=30.0, elevation_deg=70.0)
    world = wd.World()
    entities = []
    for k in range(6):
        entity = world.spawn(f'b{k}', 'football_ros://american', [0, 0, 0], UPRIGHT)
        world.throw(entity, run_of(lob, entity.name))
        entities.append(entity)
    world.step(100, 0.001, 0)
    world.y[entities[2].slot, 3] = np.nan  # one lane goes bad: the others fly on unchanged
    out = {e.name: s for e, s in world.step(1234, 0.001, 0)}
    assert 'b2' not in out and 'non-finite' in entities[2].run.ended
    flight = Flight.from_release(lob)
    for name in ('b0', 'b1', 'b3', 'b4', 'b5'):
        assert _exact(out[name], flight, 1.334)


def test_rest_pose_due_at_once_then_at_the_hold_rate_until_thrown():
    world = wd.World()
    entity = world.spawn('r', 'football_ros://american', [1.0, 2.0, 0.5], UPRIGHT)

    def due(wall_ns, hold_rate):
        return entity.slot in world.due(wall_ns, hold_rate).tolist()

    assert due(10, 2.0) and not due(10 + 499_999_999, 2.0)
    assert due(10 + 500_000_000, 2.0)
    assert not due(10**12, 0.0)  # hold_rate 0: only once
    world.place(entity, [3.0, 0.0, 0.0], UPRIGHT)  # placed elsewhere: due at once again
    assert due(10**12, 0.0) and entity.state()[0].tolist() == [3.0, 0.0, 0.0]
    world.throw(entity, run_of(Release(), 'r'))
    assert not due(10**13, 2.0)  # flying: its flight is published instead
    world.reset(state=True, spawned=False)
    assert due(10**13, 0.0) and entity.state()[0].tolist() == [1.0, 2.0, 0.5]
    assert world.default.slot not in world.due(10**14, 1.0)  # the default at rest: not shown
