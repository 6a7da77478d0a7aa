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
The viewer node against a running simulator, through a headless Foxglove WebSocket client.

The client decodes every ROS message by the schema the server advertised (not by football_ros
or rclpy), so the served schemas are checked along with the values.
"""

import math
import re

from cli_run import run_cli
from football_ros.physics import Flight, PRESETS, Release
from foxglove_client import FoxgloveClient
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from rosutil import call, landed_event, order_flight
from simulation_interfaces.srv import SpawnEntity

BALL = PRESETS['american']
RATE = 100.0


def _url(node) -> str:
    return re.search(r'ws://[0-9.]+:\d+', node.log()).group(0)


def _stamp(header) -> int:
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


def _spawn(collector, name, position):
    request = SpawnEntity.Request(name=name, uri='football_ros://american')
    p = request.initial_pose.pose.position
    p.x, p.y, p.z = position
    request.initial_pose.pose.orientation.w = 1.0
    return call(collector, SpawnEntity, '/football_simulator/spawn_entity', request, 20.0)


def _viewers_of(collector, topic):
    return collector.node.count_subscribers(topic)


def test_live_flight_tf_pose_and_scene_decoded_against_the_flight(start_node, collector):
    start_node('simulator', '--ros-args', '-p', f'publish_rate:={RATE}', '-p', 'hold_rate:=5.0')
    view = start_node('view', '--port', '0')
    assert _spawn(collector, 'ball2', (3.0, -4.0, 0.5)).result.result == 1  # RESULT_OK
    client = FoxgloveClient(_url(view))
    try:
        wanted = ('/tf', '/football/pose', '/football/scene', '/football/ball2/pose')
        client.wait_for(lambda: all(t in client.channels for t in wanted), 20.0, 'the channels')
        pose_channel = client.channels['/football/pose']
        assert (pose_channel['encoding'], pose_channel['schemaEncoding'],
                pose_channel['schemaName']) == ('cdr', 'ros2msg', 'geometry_msgs/msg/PoseStamped')
        assert client.channels['/football/scene']['schemaName'] == 'foxglove.SceneUpdate'
        # Nobody subscribed: the node reads nothing (a vanished viewer costs nothing).
        assert _viewers_of(collector, '/football/pose') == 0
        client.subscribe(*wanted)
        client.wait_for(lambda: '/football/ball2/pose' in client.messages, 20.0, 'ball2')
        client.wait_for(lambda: _viewers_of(collector, '/football/pose') == 1, 20.0, 'the reader')
        order_flight(collector, Release(), 'view-1')
        collector.wait_for(lambda: landed_event(collector), 30.0, 'the landing')
        client.poll(1.5)  # the held states after the landing, and the last scene updates
    finally:
        client.close()
    expected = Flight.from_release(Release()).simulate(rate=RATE)
    poses = [m for _, _, m in client.messages['/football/pose']]
    got = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in poses])
    flying = got[got[:, 0] > 0.0]  # the thrown ball, from its release on
    assert len(flying) > 0.8 * len(expected.times)  # best effort: nearly every tick arrives
    # Each decoded pose is a state of the flight, in order, and it lands where the flight does.
    index = [int(np.argmin(np.linalg.norm(expected.positions - p, axis=1))) for p in flying]
    assert max(np.linalg.norm(expected.positions[index] - flying, axis=1)) < 1e-6
    assert index == sorted(index) and index[-1] == len(expected.times) - 1
    by_stamp = {_stamp(m.header): m.pose for m in poses}
    transforms = [t for _, _, m in client.messages['/tf'] for t in m.transforms]
    matched = 0
    for t in transforms:
        pose = by_stamp.get(_stamp(t.header))
        if t.child_frame_id == 'football' and pose is not None:
            tr = t.transform.translation
            assert (tr.x, tr.y, tr.z) == (pose.position.x, pose.position.y, pose.position.z)
            matched += 1
    assert matched > 0.8 * len(expected.times)
    assert {t.child_frame_id for t in transforms} == {'football', 'football/ball2'}
    # The scene's last update: both balls as spheroids where they are, at their attitude.
    scene = client.messages['/football/scene'][-1][2]
    entities = {e['id']: e for e in scene['entities']}
    sphere = entities['ball/football']['spheres'][0]
    p = sphere['pose']['position']
    assert np.allclose([p['x'], p['y'], p['z']], expected.positions[-1], atol=1e-6)
    q = sphere['pose']['orientation']
    last = poses[-1].pose.orientation
    assert np.allclose([q['x'], q['y'], q['z'], q['w']], [last.x, last.y, last.z, last.w])
    assert (sphere['size']['x'], sphere['size']['y']) == (BALL.length, BALL.diameter)
    p2 = entities['ball/ball2']['spheres'][0]['pose']['position']
    assert (p2['x'], p2['y'], p2['z']) == (3.0, -4.0, 0.5)
    trail = np.array([[q['x'], q['y'], q['z']] for q in entities['trail/football']['lines'][0][
        'points']])
    assert len(trail) > 20
    assert max(np.min(np.linalg.norm(expected.positions - t, axis=1)) for t in trail) < 1e-6
    assert {'field', 'ball/football', 'ball/ball2', 'trail/football'} <= set(entities)
    # The client left: the node stops reading the topics.
    collector.wait_for(lambda: _viewers_of(collector, '/football/pose') == 0, 20.0, 'no reader')
    assert view.stop() == 0


def test_a_recorded_bag_is_served_with_its_scene(start_node, collector, tmp_path):
    bag = tmp_path / 'bag'
    start_node('simulator', '--ros-args', '-p', f'publish_rate:={RATE}')
    recorder = start_node('record', '--out', str(bag), '--topics', '/tf', 'football/pose',
                          'football/odom', '/diagnostics')
    recorder.wait_for_log("recording '/diagnostics'")
    order_flight(collector, Release(), 'view-bag')
    collector.wait_for(lambda: landed_event(collector), 30.0, 'the landing')
    assert recorder.stop() == 0
    view = start_node('view', '--port', '0', '--bag', str(bag))
    client = FoxgloveClient(_url(view))
    try:
        client.wait_for(lambda: '/football/pose' in client.channels, 20.0, 'the channels')
        assert 'Time' in client.server_info['capabilities'] or client.server_info['capabilities']
        client.subscribe('/football/pose', '/football/scene')
        expected = Flight.from_release(Release()).simulate(rate=RATE)
        end = expected.positions[-1]

        def landed():
            poses = client.messages.get('/football/pose', [])
            return poses and abs(poses[-1][2].pose.position.x - end[0]) < 1e-6

        client.wait_for(landed, 60.0, 'the played landing')
        client.poll(0.5)
    finally:
        client.close()
    poses = client.messages['/football/pose']
    assert len(poses) >= len(expected.times)  # from a file nothing is lost
    log_times = [t for _, t, _ in poses]
    assert log_times == sorted(log_times)
    assert client.times and max(client.times) <= log_times[-1] + 10**9
    scene = {e['id']: e for e in client.messages['/football/scene'][-1][2]['entities']}
    p = scene['ball/football']['spheres'][0]['pose']['position']
    assert np.allclose([p['x'], p['y'], p['z']], end, atol=1e-6)
    assert view.stop() == 0


def test_bad_options_and_a_public_address(start_node, tmp_path):
    proc = run_cli('view', '--bag', str(tmp_path / 'none'), timeout=60)
    assert proc.returncode == 2 and "parameter 'bag'" in proc.stderr
    proc = run_cli('view', '--port', '70000', timeout=60)
    assert proc.returncode == 2 and "'port'" in proc.stderr
    proc = run_cli('view', '--port', '0', '--ros-args', '-p', 'topics:=[bad name]', timeout=60)
    assert proc.returncode == 2 and "parameter 'topics'" in proc.stderr
    view = start_node('view', '--host', '0.0.0.0', '--port', '0')
    assert 'no authentication' in view.log()
    busy = re.search(r':(\d+)$', _url(view)).group(1)
    proc = run_cli('view', '--host', '0.0.0.0', '--port', busy, timeout=60)
    assert proc.returncode == 2 and f'cannot serve on 0.0.0.0:{busy}' in proc.stderr
    assert view.stop() == 0


@pytest.fixture(scope='module')
def lone_view(tmp_path_factory):
    from conftest import NodeProcess

    node = NodeProcess('view', '--port', '0', log_dir=tmp_path_factory.mktemp('view'))
    node.wait_for_log('ready')
    yield node
    assert node.stop() == 0


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.one_of(st.binary(max_size=64), st.text(max_size=64),
                          st.sampled_from(['{"op":"subscribe","subscriptions":[{"id":1}]}',
                                           '{"op":"unsubscribe","subscriptionIds":[1e308]}',
                                           '{"op":"subscribe","subscriptions":[{"id":1,'
                                           '"channelId":-1}]}'])),
                max_size=5))
def test_hostile_frames_leave_the_server_serving(lone_view, frames):
    client = FoxgloveClient(_url(lone_view))
    try:
        client.wait_for(lambda: '/football/scene' in client.channels, 20.0, 'the scene channel')
        for frame in frames:
            client.ws.send(frame)
    except Exception:  # noqa: BLE001 - the server may close a connection that misbehaves
        pass
    finally:
        client.close()
    again = FoxgloveClient(_url(lone_view))
    try:
        again.wait_for(lambda: '/football/scene' in again.channels, 20.0, 'the scene channel')
        again.subscribe('/football/scene')
        again.wait_for(lambda: again.messages.get('/football/scene'), 20.0, 'a scene')
        field = again.messages['/football/scene'][-1][2]['entities'][0]
        assert field['id'] == 'field' and all(
            math.isfinite(p['x']) for p in field['lines'][0]['points'])
    finally:
        again.close()
