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

"""SpawnEntities, GetEntityBounds, balls at rest on their topics and TF, SimulateSteps cancel."""

import math
import re

from football_ros.physics import Flight, Release
from football_ros.physics.presets import get_preset
from geometry_msgs.msg import PoseStamped
import numpy as np
import pytest
from rosutil import call

si_srv = pytest.importorskip(
    'simulation_interfaces.srv', reason='simulation_interfaces not built (scripts/setup.sh)'
)
from simulation_interfaces.action import SimulateSteps  # noqa: E402
from simulation_interfaces.msg import (  # noqa: E402
    Bounds,
    EntityState,
    Result,
    SimulationState,
    SimulatorFeatures,
    SpawnEntity,
)

NODE = '/football_simulator'
OK, NOT_FOUND, FAILED = Result.RESULT_OK, Result.RESULT_NOT_FOUND, Result.RESULT_OPERATION_FAILED


def srv(collector, name, srv_type, **fields):
    return call(collector, srv_type, f'{NODE}/{name}', srv_type.Request(**fields), timeout=20.0)


def spawn_request(name, position=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0)):
    request = SpawnEntity(name=name)
    request.entity_resource.uri = 'football_ros://american'
    p, q = request.initial_pose.pose.position, request.initial_pose.pose.orientation
    p.x, p.y, p.z = position
    q.x, q.y, q.z, q.w = orientation
    return request


def test_spawn_entities_bounds_and_balls_at_rest_on_their_topics_and_tf(start_node, collector):
    from football_ros.nodes import qos
    from tf2_msgs.msg import TFMessage

    start_node('simulator', '--ros-args', '-p', 'max_entities:=4', '-p', 'hold_rate:=5.0')
    collector.subscribe(PoseStamped, 'football/r1/pose', qos.STATE)
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    features = srv(collector, 'get_simulator_features', si_srv.GetSimulatorFeatures).features
    assert {SimulatorFeatures.SPAWNING_ENTITIES, SimulatorFeatures.ENTITY_BOUNDS} <= set(
        features.features
    )
    half = math.sqrt(0.5)
    spawns = [
        spawn_request('r1', (1.0, 2.0, 0.5), (0.0, 0.0, half, half)),  # turned 90 deg about z
        spawn_request('bad name'),
        spawn_request('r3', (math.nan, 0.0, 0.0)),
        spawn_request('r4'),
        spawn_request('r5'),  # football + r1 + r4 + r5 = the limit of 4
        spawn_request('r6'),
    ]
    answer = srv(collector, 'spawn_entities', si_srv.SpawnEntities, spawn_requests=spawns)
    assert answer.result.result == si_srv.SpawnEntities.Response.ENTITIES_SPAWN_FAILED
    assert '3 of 6' in answer.result.error_message
    R = si_srv.SpawnEntity.Response
    codes = [r.result.result for r in answer.results]
    assert codes == [OK, R.NAME_INVALID, R.INVALID_POSE, OK, OK, FAILED]
    assert 'limit of 4' in answer.results[5].result.error_message
    assert [r.entity_name for r in answer.results if r.result.result == OK] == ['r1', 'r4', 'r5']
    too_many = [spawn_request(f'x{k}') for k in range(1001)]
    answer = srv(collector, 'spawn_entities', si_srv.SpawnEntities, spawn_requests=too_many)
    assert answer.result.result == FAILED and '1001' in answer.result.error_message
    assert not answer.results

    # At rest where spawned: its pose topic and TF (held at hold_rate), zero velocity.
    collector.wait_for(lambda: collector.get('football/r1/pose'), 10.0, 'the rest pose')
    pose = collector.get('football/r1/pose')[-1].pose
    assert [pose.position.x, pose.position.y, pose.position.z] == [1.0, 2.0, 0.5]
    assert [pose.orientation.z, pose.orientation.w] == pytest.approx([half, half], abs=1e-15)

    def rest_transforms():
        return [
            t for m in collector.get(qos.TF) for t in m.transforms
            if t.child_frame_id == 'football/r1'
        ]

    collector.wait_for(lambda: len(rest_transforms()) >= 2, 10.0, 'the held transforms')
    tf = rest_transforms()[-1].transform.translation
    assert [tf.x, tf.y, tf.z] == [1.0, 2.0, 0.5]
    stamps = [t.header.stamp.sec * 10**9 + t.header.stamp.nanosec for t in rest_transforms()]
    assert stamps == sorted(set(stamps))  # tf2: never a repeated stamp
    state = srv(collector, 'get_entity_state', si_srv.GetEntityState, entity='r1').state
    assert [state.pose.position.x, state.twist.linear.z] == [1.0, 0.0]

    bounds = srv(collector, 'get_entity_bounds', si_srv.GetEntityBounds, entity='r4')
    preset = get_preset('american')
    assert bounds.result.result == OK and bounds.bounds.type == Bounds.TYPE_BOX
    lo, hi = bounds.bounds.points
    assert [hi.x, hi.y, hi.z] == [0.5 * preset.length, 0.5 * preset.diameter,
                                  0.5 * preset.diameter]
    assert [lo.x, lo.y, lo.z] == [-hi.x, -hi.y, -hi.z]
    for name in ('nobody', '', 'r1' * 100):
        answer = srv(collector, 'get_entity_bounds', si_srv.GetEntityBounds, entity=name)
        assert answer.result.result == NOT_FOUND


def test_simulate_steps_cancel_stops_at_a_step_boundary(start_node, collector):
    from rclpy.action import ActionClient
    from action_msgs.msg import GoalStatus

    start_node('simulator', '--ros-args', '-p', 'max_entities:=250')
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    assert srv(collector, 'set_simulation_state', si_srv.SetSimulationState,
               state=paused).result.result == OK
    release = Release(speed=60.0, elevation_deg=80.0)  # 12 s in the air
    st = release.initial_state()
    # 200 balls: the goal takes about a second, so that the cancel lands while it runs even on a
    # loaded machine (with 40, the whole goal sometimes ended before the cancel was handled).
    spawns = [spawn_request(f'b{k}') for k in range(200)]
    answer = srv(collector, 'spawn_entities', si_srv.SpawnEntities, spawn_requests=spawns)
    assert answer.result.result == OK
    for k in range(200):
        state = EntityState()
        o = state.pose.orientation
        o.x, o.y, o.z, o.w = st.attitude.tolist()
        v, w = state.twist.linear, state.twist.angular
        v.x, v.y, v.z = st.velocity.tolist()
        w.x, w.y, w.z = st.angular_velocity().tolist()
        assert srv(collector, 'set_entity_state', si_srv.SetEntityState, entity=f'b{k}',
                   state=state).result.result == OK

    action = ActionClient(collector.node, SimulateSteps, f'{NODE}/simulate_steps')
    assert action.wait_for_server(timeout_sec=20.0)
    feedback = []
    steps = 600_000  # the most one goal may take (600 s of flight), in chunks of ~20 ms CPU
    sent = action.send_goal_async(
        SimulateSteps.Goal(steps=steps), feedback_callback=lambda f: feedback.append(f.feedback)
    )
    collector.wait_for(sent.done, 20.0, 'goal accepted')
    handle = sent.result()
    assert handle.accepted
    # A second goal while this one runs is rejected (one at a time).
    second = action.send_goal_async(SimulateSteps.Goal(steps=10))
    cancel = handle.cancel_goal_async()
    collector.wait_for(cancel.done, 20.0, 'cancel answered')
    collector.wait_for(second.done, 20.0, 'second goal answered')
    assert not second.result().accepted
    done = handle.get_result_async()
    collector.wait_for(done.done, 60.0, 'goal result')
    assert done.result().status == GoalStatus.STATUS_CANCELED
    outcome = done.result().result.result
    assert outcome.result == FAILED
    ran, total = map(int, re.fullmatch(
        r'canceled after (\d+) of (\d+) steps', outcome.error_message).groups())
    assert total == steps and ran < steps
    # Stopped at a chunk's end: the last feedback tells the steps done.
    collector.wait_for(lambda: feedback and feedback[-1].completed_steps == ran,
                       5.0, 'the last feedback')
    if feedback:
        assert feedback[-1].remaining_steps == steps - ran
    # The world stopped exactly there: the state is the offline flight's after `ran` steps.
    got = srv(collector, 'get_entity_state', si_srv.GetEntityState, entity='b7').state.pose
    want = Flight.from_release(release).sample(ran * 0.001).position
    np.testing.assert_allclose(
        [got.position.x, got.position.y, got.position.z], want, rtol=0, atol=1e-9
    )
    # The next goal runs to the end; its feedback (one per chunk but the last, if it took more
    # than one) never repeats what the result says.
    feedback.clear()
    sent = action.send_goal_async(
        SimulateSteps.Goal(steps=100), feedback_callback=lambda f: feedback.append(f.feedback)
    )
    collector.wait_for(sent.done, 20.0, 'goal accepted')
    done = sent.result().get_result_async()
    collector.wait_for(done.done, 20.0, 'goal result')
    assert done.result().status == GoalStatus.STATUS_SUCCEEDED
    assert done.result().result.result.result == OK
    assert all(0 < f.completed_steps < 100 == f.completed_steps + f.remaining_steps
               for f in feedback)
    got = srv(collector, 'get_entity_state', si_srv.GetEntityState, entity='b7').state.pose
    want = Flight.from_release(release).sample((ran + 100) * 0.001).position
    np.testing.assert_allclose(
        [got.position.x, got.position.y, got.position.z], want, rtol=0, atol=1e-9
    )


def test_a_finished_goals_result_is_kept_for_goal_result_timeout(start_node, collector):
    """The result is there when asked for at once, and gone (UNKNOWN) after the window."""
    from action_msgs.msg import GoalStatus
    from rclpy.action import ActionClient

    start_node('simulator', '--ros-args', '-p', 'goal_result_timeout:=0.5')
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    assert srv(collector, 'set_simulation_state', si_srv.SetSimulationState,
               state=paused).result.result == OK
    action = ActionClient(collector.node, SimulateSteps, f'{NODE}/simulate_steps')
    assert action.wait_for_server(timeout_sec=20.0)
    sent = action.send_goal_async(SimulateSteps.Goal(steps=10))
    collector.wait_for(sent.done, 20.0, 'goal accepted')
    handle = sent.result()
    first = handle.get_result_async()
    collector.wait_for(first.done, 20.0, 'the result')
    assert first.result().status == GoalStatus.STATUS_SUCCEEDED
    assert first.result().result.result.result == OK
    asked = []

    def expired() -> bool:  # ask again until the server has let the result go
        if not asked or asked[-1].done():
            if asked and asked[-1].result().status == GoalStatus.STATUS_UNKNOWN:
                return True
            asked.append(handle.get_result_async())
        return False

    collector.wait_for(expired, 20.0, 'the result to expire')
    assert all(f.result().status in (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_UNKNOWN)
               for f in asked)


@pytest.mark.parametrize('frame_id', ['field', 'f', 'abc', 'abcdefgh', 'x' * 13])
def test_entity_messages_bytes_decode_to_the_messages(frame_id):
    """The hand-made CDR of pose, odom and TF decodes (rclpy) to the messages it stands for."""
    from football_ros.nodes import messages as mb
    from geometry_msgs.msg import TransformStamped
    from nav_msgs.msg import Odometry
    from rclpy.serialization import deserialize_message, serialize_message
    from tf2_msgs.msg import TFMessage

    rng = np.random.default_rng(len(frame_id))
    expected_tf, items = TFMessage(), []
    for child in ('football/a', 'football/bb', 'football/ccc', 'football/dddd', 'football/é'):
        msgs = mb.EntityMessages(frame_id, child)
        stamp = mb.time_msg(int(rng.integers(0, 2**60)))
        p, q = rng.uniform(-1e3, 1e3, 3).tolist(), rng.uniform(-1.0, 1.0, 4).tolist()
        v, w = rng.uniform(-50.0, 50.0, 3).tolist(), rng.uniform(-1e3, 1e3, 3).tolist()
        pose = PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp, frame_id
        pose.pose = mb.pose_of(p, q)
        mine = msgs.pose(stamp, p, q)
        assert deserialize_message(mine, PoseStamped) == pose
        assert len(mine) == len(serialize_message(pose))
        odom = Odometry(child_frame_id=child)
        odom.header = pose.header
        odom.pose.pose = pose.pose
        odom.twist.twist = mb.twist_of(mb.to_body_frame(q, v), mb.to_body_frame(q, w))
        assert deserialize_message(msgs.odom(stamp, p, q, v, w), Odometry) == odom
        transform = TransformStamped(header=pose.header, child_frame_id=child)
        transform.transform.translation = mb.vector3(p)
        transform.transform.rotation = mb.quaternion(q)
        expected_tf.transforms.append(transform)
        items.append((msgs, stamp, p, q))
        mine = mb.tf_message_bytes(items)  # 1 to 5 transforms, every alignment
        assert deserialize_message(mine, TFMessage) == expected_tf
        assert len(mine) == len(serialize_message(expected_tf))
