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

"""The ROS-free simulation core: one tick path, lock-step, play/pause/stop, filters, states."""

import subprocess
import sys

from football_ros.physics import dynamics as dyn, Flight, Release
from football_ros.simulation import core, world as wd
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

UPRIGHT = [0.0, 0.0, 0.0, 1.0]
PERIOD_NS = 10_000_000  # 100 Hz


def run(release: Release, label: str = 'r') -> wd.FlightRun:
    return wd.FlightRun(label, Flight.from_release(release))


def test_no_ros_imported():
    code = (
        'import sys, football_ros.simulation.core; '
        "print([m for m in sys.modules if m.split('.')[0] in ('rclpy', 'rcl_interfaces')])"
    )
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == '[]'


def test_default_and_spawned_balls_take_the_same_path_bit_for_bit():
    sim = core.Simulation()
    sim.spawn('twin', 'football_ros://american', [0, 0, 0], UPRIGHT)
    release = Release(alpha0_deg=2.0, beta0_deg=-1.0)
    sim.throw(wd.DEFAULT_ENTITY, run(release, 'a'))
    sim.throw('twin', run(release, 'b'))
    offline = Flight.from_release(release)
    theory = Flight.from_release(release)  # its theories advanced frame by frame
    ticks = 0
    while sim.entity_state('twin').condition == 'flying':
        frame = sim.tick(ticks * PERIOD_NS, PERIOD_NS, 1.0, 0.0)
        if ticks % 2:
            sim.integrate_ahead()  # computed ahead or not: the same bits
        assert frame.shown.tolist() == [0, 1]
        assert np.array_equal(frame.pose[0], frame.pose[1])
        assert np.array_equal(frame.twist[0], frame.twist[1])
        state = offline.state_at(ticks * 0.01)  # tick k shows k x 0.01 s of flight
        if offline.landing_time is None:
            assert np.array_equal(frame.pose[0, :3], state[dyn.R:dyn.R + 3])
            linear, quasi = theory.theory_angles(ticks * 0.01, state)  # every frame
            if ticks % 3 == 0:  # the sample read on some frames only: the same theory
                sample = frame.default.sample
                assert np.array_equal(sample.position, frame.pose[0, :3])
                assert np.array_equal(sample.aero_angles_linear, linear)
                assert np.array_equal(sample.aero_angles_quasi_steady, quasi)
                assert np.isfinite(quasi).all()
        ticks += 1
    landed = [e for e in sim.drain_events()[0] if e[1] == 'landed']
    assert [e[3] for e in landed] == ['a', 'b']
    assert sim.entity_state('twin').position[2] == 0.0
    assert ticks == int(offline.landing_time // 0.01) + 2  # t = 0 .. 2.79 s, then the landing


def test_lock_step_equals_the_offline_flight_and_leaves_the_clock_on():
    sim = core.Simulation(step=0.001)
    release = Release(speed=20.0)
    sim.throw(wd.DEFAULT_ENTITY, run(release))
    sim.set_state(core.PAUSED)
    assert sim.tick(0, PERIOD_NS, 1.0, 1.0).shown.size == 0  # paused: nothing flies
    assert sim.clock_ns == 0
    offline = Flight.from_release(release)
    done = 0
    for n in (1, 7, 250, 1000):
        frame = sim.step_n(n, 0)
        done += n
        want = offline.state_at(done * 0.001)
        assert np.array_equal(frame.pose[0, :3], want[dyn.R:dyn.R + 3])
        assert sim.clock_ns == done * 1_000_000
    assert sim.state == core.PAUSED


def test_acceleration_is_the_models():
    sim = core.Simulation()
    sim.spawn('p', 'football_ros://american', [0, 0, 0], UPRIGHT)
    sim.spawn('f', 'football_ros://american', [0, 0, 0], UPRIGHT)
    sim.throw('p', run(Release(model='paper')))
    sim.throw('f', run(Release(model='full')))
    sim.set_state(core.PAUSED)
    sim.step_n(500, 0)
    paper, full = sim.entity_state('p'), sim.entity_state('f')
    np.testing.assert_allclose(paper.acceleration, [0.0, 0.0, -9.81], rtol=0, atol=1e-12)
    # The full model: drag slows the ball; the same as the velocity's central difference.
    v0 = full.velocity
    sim.step_n(1, 0)
    v1 = sim.entity_state('f').velocity
    a1 = sim.entity_state('f').acceleration
    np.testing.assert_allclose((v1 - v0) / 0.001, 0.5 * (full.acceleration + a1), atol=1e-5)
    assert np.dot(full.acceleration - [0, 0, -9.81], full.velocity) < 0
    sim.place('f', [1.0, 2.0, 0.0], UPRIGHT)
    assert not sim.entity_state('f').acceleration.any()  # at rest


def test_stop_and_reset_scopes():
    sim = core.Simulation()
    sim.spawn('a', 'football_ros://rugby', [1.0, 0.0, 0.0], UPRIGHT)
    sim.throw('a', run(Release(ball='rugby')))
    sim.throw(wd.DEFAULT_ENTITY, run(Release()))
    for k in range(5):
        sim.tick(k * PERIOD_NS, PERIOD_NS, 1.0, 1.0)
    assert sim.clock_ns == 5 * PERIOD_NS
    assert [d.name for d in sim.reset(time=True, state=False, spawned=False)] == []
    assert sim.clock_ns == 0 and sim.entity_state('a').condition == 'flying'
    sim.reset(time=False, state=True, spawned=False)
    assert sim.entity_state('a').position.tolist() == [1.0, 0.0, 0.0]
    assert sim.run_of(wd.DEFAULT_ENTITY) is None
    sim.throw('a', run(Release(ball='rugby')))
    doomed = sim.set_state(core.STOPPED)
    assert [d.name for d in doomed] == ['a'] and sim.select() == [wd.DEFAULT_ENTITY]
    assert sim.state == core.STOPPED and sim.clock_ns == 0


def test_a_change_after_integrating_ahead_is_honoured():
    sim = core.Simulation()
    sim.spawn('a', 'football_ros://american', [0, 0, 0], UPRIGHT)
    sim.throw('a', run(Release()))
    sim.tick(0, PERIOD_NS, 1.0, 1.0)
    sim.integrate_ahead()
    sim.place('a', [5.0, 0.0, 1.0], UPRIGHT)
    frame = sim.tick(PERIOD_NS, PERIOD_NS, 1.0, 1.0)
    assert frame.shown.tolist() == [1] and frame.held.tolist() == [True]
    assert frame.pose[0, :3].tolist() == [5.0, 0.0, 1.0] and not frame.twist.any()


def _paced(rest: bool, changes: dict) -> tuple[list, int, int]:
    """
    Tick 1000 periods at 100 Hz, hold rate 2 Hz; ``changes`` {tick: f(sim)} made before it.

    ``rest``: skip the ticks :meth:`core.Simulation.quiet_until` says show nothing, as the
    node's pacer does, until the next change. Returns every frame shown (tick, rows, poses,
    clock), the clock at the end and the ticks skipped.
    """
    sim = core.Simulation()
    shown, k, skipped = [], 0, 0
    while k < 1000:
        if k in changes:
            changes[k](sim)
        frame = sim.tick(k * PERIOD_NS, PERIOD_NS, 1.0, 2.0)
        if frame.shown.size:
            shown.append((k, frame.shown.tolist(), frame.pose.tolist(), sim.clock_ns))
        sim.drain_events()
        k += 1
        if rest:
            quiet = sim.quiet_until(k * PERIOD_NS, 2.0)
            wake = min([c for c in changes if c >= k] + [1000])
            if quiet is not None:
                wake = min(wake, -(-quiet // PERIOD_NS))  # the first tick at or after it
            if wake > k:
                sim.skip(wake - k, PERIOD_NS, 1.0)
                skipped += wake - k
                k = wake
    return shown, sim.clock_ns, skipped


def test_a_resting_pacer_skips_only_ticks_that_show_nothing():
    changes = {
        0: lambda s: s.spawn('a', 'football_ros://american', [1.0, 0.0, 0.0], UPRIGHT),
        120: lambda s: s.throw('a', run(Release(speed=12.0, elevation_deg=40.0))),
        130: lambda s: s.throw(wd.DEFAULT_ENTITY, run(Release(speed=8.0, elevation_deg=30.0))),
        400: lambda s: s.set_state(core.PAUSED),
        430: lambda s: s.spawn('b', 'football_ros://rugby', [0.0, 2.0, 0.0], UPRIGHT),
        450: lambda s: s.step_n(300, 0),
        610: lambda s: s.set_state(core.PLAYING),
        700: lambda s: s.place('b', [3.0, 2.0, 0.5], UPRIGHT),
        720: lambda s: s.throw('b', run(Release(ball='rugby', speed=9.0))),
        900: lambda s: s.reset(time=False, state=True, spawned=False),
    }
    every, clock, none = _paced(False, changes)
    rested, rested_clock, skipped = _paced(True, changes)
    assert rested == every
    assert rested_clock == clock == 790 * PERIOD_NS + 300 * 1_000_000  # paused 400-609
    assert none == 0 and skipped > 600  # at rest most of the time: held at 2 Hz
    assert any(len(rows) == 2 for _, rows, _, _ in every)  # both balls in the air at once


def test_every_change_a_tick_shows_wakes_the_pacer():
    sim = core.Simulation()
    changes = [
        lambda: sim.spawn('a', 'football_ros://american', [0, 0, 0], UPRIGHT),
        lambda: sim.place('a', [1.0, 0.0, 0.0], UPRIGHT),
        lambda: sim.throw('a', run(Release(speed=10.0))),
        lambda: sim.set_state(core.PAUSED),
        lambda: sim.step_n(5000, 0),  # lands: an event to report
        lambda: sim.reset(time=True, state=True, spawned=False),
        lambda: sim.report('WARN', 'x', 'y'),
        lambda: sim.delete('a'),
    ]
    for change in changes:
        sim.changed.clear()
        change()
        assert sim.changed.is_set()
    sim.spawn('b', 'football_ros://american', [0, 0, 0], UPRIGHT)
    sim.throw('b', run(Release(speed=30.0)))
    sim.drain_events()
    sim.changed.clear()
    sim.step_n(10, 0)  # lock-step shows its own frame: no wake, no event
    sim.entity_state('b')
    assert not sim.changed.is_set()
    assert sim.quiet_until(5, 1.0) is None  # paused, b in the air: no tick has work
    sim.set_state(core.PLAYING)
    assert sim.quiet_until(5, 1.0) == 5  # playing: every tick moves b


def test_deleting_a_ball_keeps_every_other_balls_numbers():
    sim = core.Simulation()
    for k in range(5):
        sim.spawn(f'b{k}', 'football_ros://american', [float(k), 0, 0], UPRIGHT)
        sim.throw(f'b{k}', run(Release(speed=10.0 + k, position=(float(k), 0.0, 0.0))))
    sim.set_state(core.PAUSED)
    sim.step_n(300, 0)
    before = {n: sim.entity_state(n).position for n in ('b0', 'b2', 'b3', 'b4')}
    sim.delete('b1')  # the last row moves into its place
    after = {n: sim.entity_state(n).position for n in before}
    assert all(np.array_equal(before[n], after[n]) for n in before)
    sim.step_n(200, 0)
    for k in (0, 2, 3, 4):
        want = Flight.from_release(Release(speed=10.0 + k, position=(float(k), 0.0, 0.0)))
        np.testing.assert_array_equal(
            sim.entity_state(f'b{k}').position, want.state_at(0.5)[dyn.R:dyn.R + 3]
        )


@pytest.mark.parametrize('pattern, hits', [
    ('.*' * 30 + 'X', []),
    ('(a+)+$', ['b' + 'a' * 60]),
    ('(.*a){20}$', ['b' + 'a' * 60]),
    ('(x+x+)+y', []),
])
def test_backtracking_patterns_are_matched_by_an_automaton(pattern, hits):
    # Each of these makes a backtracking engine (Python's re) run for hours on these names.
    sim = core.Simulation(max_entities=200)
    for k in range(150):
        sim.spawn('a' * 58 + f'_{k}', 'football_ros://american', [0, 0, 0], UPRIGHT)
    sim.spawn('b' + 'a' * 60, 'football_ros://american', [0, 0, 0], UPRIGHT)
    assert sim.select(pattern) == hits


@settings(max_examples=300, deadline=None)
@given(pattern=st.text(max_size=300))
def test_fuzz_filters_refuse_or_match(pattern):
    sim = core.Simulation()
    sim.spawn('ball_one', 'football_ros://american', [0, 0, 0], UPRIGHT)
    try:
        got = sim.select(pattern)
    except wd.EntityError as exc:
        assert exc.reason == 'filter' and 'filter' in str(exc)
    else:
        assert set(got) <= {wd.DEFAULT_ENTITY, 'ball_one'}
