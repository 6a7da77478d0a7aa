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

"""The viewer's scene (football_ros/scene.py) and the bag player's clock, without ROS."""

import json
import math

from football_ros.physics import Flight, PRESETS, Release
from football_ros.physics.frames import body_x_axis, quaternion_to_matrix
from football_ros.playback import MAX_SPEED, PlaybackClock
from football_ros.scene import (
    arc_from_x,
    CHI2_2D_95,
    ellipse_points,
    FIELD_WIDTH,
    MAX_BALLS,
    MAX_PATH_POINTS,
    Scene,
    scene_role,
    SceneError,
    TRAIL_POINTS,
    VELOCITY_SCALE,
)
from hypothesis import example, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

BALL = PRESETS['american']


def _finite(text):
    raise AssertionError(f'{text} in the JSON')


def _load(text):
    """Parse a scene update; AssertionError on NaN or infinities."""
    return json.loads(text, parse_constant=_finite)


def _entities(update):
    return {e['id']: e for e in _load(update)['entities']}


def _q(d):
    o = d['orientation']
    return np.array([o['x'], o['y'], o['z'], o['w']])


def _p(d):
    return np.array([d['x'], d['y'], d['z']])


def test_a_flight_as_a_scene_spheroid_axis_velocity_trail():
    flight = Flight.from_release(Release()).simulate(rate=100.0)
    scene = Scene(BALL.length, BALL.diameter)
    for i, t in enumerate(flight.times):
        scene.ball('football', int(t * 1e9), flight.positions[i], flight.orientations[i],
                   flight.velocities[i])
    ents = _entities(scene.update(123))
    sphere = ents['ball/football']['spheres'][0]
    assert (sphere['size']['x'], sphere['size']['y'], sphere['size']['z']) == (
        BALL.length, BALL.diameter, BALL.diameter)
    assert np.allclose(_p(sphere['pose']['position']), flight.positions[-1])
    assert np.allclose(_q(sphere['pose']), flight.orientations[-1] /
                       np.linalg.norm(flight.orientations[-1]))
    axis_arrow, velocity_arrow = ents['ball/football']['arrows']
    # An arrow points along its pose's +x: the spin axis and the velocity.
    assert np.allclose(body_x_axis(_q(axis_arrow['pose'])), body_x_axis(flight.orientations[-1]),
                       atol=1e-9)
    v = flight.velocities[-1]
    assert np.allclose(body_x_axis(_q(velocity_arrow['pose'])), v / np.linalg.norm(v), atol=1e-9)
    length = velocity_arrow['shaft_length'] + velocity_arrow['head_length']
    assert length == pytest.approx(VELOCITY_SCALE * np.linalg.norm(v))
    trail = np.array([_p(p) for p in ents['trail/football']['lines'][0]['points']])
    assert 10 < len(trail) <= TRAIL_POINTS
    # Every trail point is a flown position, in order, ending near the last one.
    nearest = [np.min(np.linalg.norm(flight.positions - p, axis=1)) for p in trail]
    assert max(nearest) < 1e-9
    assert np.all(np.diff(trail[:, 0]) > 0)  # downfield all the way
    field = ents['field']['lines'][0]['points']
    assert max(abs(p['y']) for p in field) == pytest.approx(FIELD_WIDTH / 2)


@settings(max_examples=300, deadline=None)
@given(st.tuples(*[st.floats(-1e3, 1e3)] * 3).filter(lambda v: np.linalg.norm(v) > 1e-3))
@example((-1.0, 0.0, 4.153710205191077e-160))  # found: sums of squares underflowed (|q| 1+1e-6)
@example((-1.0, 0.0, 5e-324))
def test_arc_from_x_turns_x_onto_the_direction(v):
    q = np.array(arc_from_x(v))
    assert np.linalg.norm(q) == pytest.approx(1.0)
    assert np.allclose(body_x_axis(q), np.array(v) / np.linalg.norm(v), atol=1e-9)


def test_odometry_velocity_in_body_axes_is_drawn_in_the_field():
    scene = Scene(BALL.length, BALL.diameter)
    q = np.array([0.1, -0.3, 0.5, 0.8])
    q /= np.linalg.norm(q)
    scene.ball('b', 0, (1, 2, 3), q)
    world = np.array([12.0, -1.0, 5.0])
    scene.ball_velocity('b', quaternion_to_matrix(q).T @ world)  # body components
    scene.ball_velocity('nobody', (1, 2, 3))  # an unknown ball: ignored
    arrow = _entities(scene.update(0))['ball/b']['arrows'][1]
    assert np.allclose(body_x_axis(_q(arrow['pose'])), world / np.linalg.norm(world))


def test_the_landing_ellipse_holds_95_percent():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(3, 3))
    cov = a @ a.T + np.eye(3)
    mean = np.array([40.0, -3.0, 0.0])
    pts = ellipse_points(mean, cov)
    d = pts[:, :2] - mean[:2]
    inv = np.linalg.inv(cov[:2, :2])
    assert np.allclose(np.einsum('ni,ij,nj->n', d, inv, d), CHI2_2D_95)
    assert np.allclose(pts[:, 2], mean[2])
    # Monte Carlo: 95 % of draws fall inside.
    draws = rng.multivariate_normal(mean[:2], cov[:2, :2], 200_000) - mean[:2]
    inside = np.mean(np.einsum('ni,ij,nj->n', draws, inv, draws) <= CHI2_2D_95)
    assert inside == pytest.approx(0.95, abs=0.003)
    scene = Scene(BALL.length, BALL.diameter)
    scene.landing('prediction/landing', 5, mean, cov)
    scene.landing('track_2/prediction/landing', 5, mean, -np.eye(3))  # no ellipse: the point
    ents = _entities(scene.update(0))
    assert len(ents['landing/prediction/landing']['lines'][0]['points']) == len(pts)
    assert ents['landing/track_2/prediction/landing']['lines'] == []
    assert np.allclose(_p(ents['landing/track_2/prediction/landing']['cylinders'][0]['pose'][
        'position']), mean)


def test_paths_are_thinned_and_removal_deletes():
    scene = Scene(BALL.length, BALL.diameter)
    pts = np.column_stack([np.arange(5000.0), np.zeros(5000), np.ones(5000)])
    scene.path('prediction/path', 1, 'predicted', pts)
    scene.ball('b2', 1, (0, 0, 1), (0, 0, 0, 1))
    ents = _entities(scene.update(0))
    line = ents['path/prediction/path']['lines'][0]['points']
    assert len(line) == MAX_PATH_POINTS and line[0]['x'] == 0 and line[-1]['x'] == 4999
    scene.remove('b2')
    scene.remove('prediction/path')
    update = scene.update(0)
    deleted = {d['id'] for d in _load(update)['deletions']}
    assert deleted == {'ball/b2', 'trail/b2', 'path/prediction/path'}
    assert set(_entities(update)) == {'field'}
    assert _load(scene.update(0))['deletions'] == []
    scene.ball('b3', 1, (0, 0, 1), (0, 0, 0, 1))
    scene.landing('l', 1, (1, 2, 0), np.eye(3))
    scene.clear()
    update = _load(scene.update(0))
    assert {d['id'] for d in update['deletions']} == {'ball/b3', 'trail/b3', 'landing/l'}
    assert [e['id'] for e in update['entities']] == ['field']


@pytest.mark.parametrize('relative, kind, expected', [
    ('pose', 'geometry_msgs/msg/PoseStamped', ('ball', 'football')),
    ('ball7/pose', 'geometry_msgs/msg/PoseStamped', ('ball', 'ball7')),
    ('odom', 'nav_msgs/msg/Odometry', ('velocity', 'football')),
    ('ball7/odom', 'nav_msgs/msg/Odometry', ('velocity', 'ball7')),
    ('prediction/landing', 'geometry_msgs/msg/PoseWithCovarianceStamped',
     ('landing', 'prediction/landing')),
    ('track_3/prediction/landing', 'geometry_msgs/msg/PoseWithCovarianceStamped',
     ('landing', 'track_3/prediction/landing')),
    ('track_3/prediction/path', 'nav_msgs/msg/Path', ('predicted', 'track_3/prediction/path')),
    ('plan/path', 'nav_msgs/msg/Path', ('planned', 'plan/path')),
    ('estimate', 'nav_msgs/msg/Odometry', None),
    ('release/state', 'nav_msgs/msg/Odometry', None),
    ('prediction/catch', 'geometry_msgs/msg/PoseWithCovarianceStamped', None),
])
def test_scene_roles(relative, kind, expected):
    assert scene_role(relative, kind) == expected


def test_bounded_stores():
    scene = Scene(BALL.length, BALL.diameter)
    for i in range(MAX_BALLS):
        scene.ball(f'b{i}', 0, (0, 0, 0), (0, 0, 0, 1))
    with pytest.raises(SceneError, match='more than'):
        scene.ball('one_more', 0, (0, 0, 0), (0, 0, 0, 1))
    for i in range(3 * TRAIL_POINTS):
        scene.ball('b0', i, (i, 0, 0), (0, 0, 0, 1))
    trail = _entities(scene.update(0))['trail/b0']['lines'][0]['points']
    assert len(trail) == TRAIL_POINTS and trail[-1]['x'] == 3 * TRAIL_POINTS - 1


finite = st.floats(allow_nan=True, allow_infinity=True, width=64)


@settings(max_examples=300, deadline=None)
@given(st.lists(finite, min_size=0, max_size=6), st.lists(finite, min_size=0, max_size=6),
       st.lists(finite, min_size=0, max_size=12))
def test_hostile_inputs_are_refused_by_name_and_never_reach_the_json(p, q, cov):
    scene = Scene(BALL.length, BALL.diameter)
    for call in (
        lambda: scene.ball('x', 0, p, q, p),
        lambda: scene.ball_velocity('x', p),
        lambda: scene.landing('l', 0, p, np.resize(np.array(cov or [0.0]), (3, 3))),
        lambda: scene.path('pa', 0, 'planned', np.resize(np.array(p or [0.0]), (2, 3))),
    ):
        try:
            call()
        except SceneError as exc:
            assert str(exc).split(':')[0] in ('x', 'l', 'pa', 'landing position')
    _load(scene.update(0))  # raises on anything non-finite


def test_playback_clock_play_pause_seek_speed():
    wall = [0]
    clock = PlaybackClock(1_000, 11_000, wall=lambda: wall[0])
    assert clock.position() == 1_000 and not clock.playing
    clock.play()
    wall[0] += 2_000
    assert clock.position() == 3_000
    clock.set_speed(2.0)
    wall[0] += 1_000
    assert clock.position() == 5_000
    clock.pause()
    wall[0] += 5_000
    assert clock.position() == 5_000
    clock.seek(-5)
    assert clock.position() == 1_000
    clock.seek(10**12)
    assert clock.position() == 11_000 and clock.ended
    clock.play()  # from the start again
    assert clock.position() == 1_000
    clock.set_speed(math.inf)
    assert clock.speed == MAX_SPEED
    clock.set_speed(math.nan)
    assert clock.speed == MAX_SPEED
    wall[0] += 10**9
    assert clock.position() == 11_000  # never past the end
