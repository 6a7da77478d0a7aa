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

"""The simulator through simulation_interfaces: a generic client, hostile values, entity topics."""

import json
import math
from pathlib import Path
import subprocess
import sys

from football_ros.physics import Flight, Release
from football_ros.physics.presets import get_preset
from football_ros.physics.release import InitialState
from geometry_msgs.msg import PoseStamped
import numpy as np
import pytest
from rosutil import call, landed_event

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
)

HERE = Path(__file__).resolve().parent
NODE = '/football_simulator'
OK, NOT_FOUND, FAILED, UNSUPPORTED = (
    Result.RESULT_OK,
    Result.RESULT_NOT_FOUND,
    Result.RESULT_OPERATION_FAILED,
    Result.RESULT_FEATURE_UNSUPPORTED,
)


def srv(collector, name, srv_type, **fields):
    return call(collector, srv_type, f'{NODE}/{name}', srv_type.Request(**fields), timeout=20.0)


def throw_of(name: str, release: Release) -> dict:
    st = release.initial_state()
    return {
        'name': name,
        'uri': f'football_ros://{release.ball}',
        'position': st.position.tolist(),
        'orientation': st.attitude.tolist(),
        'velocity': st.velocity.tolist(),
        'angular_velocity': st.angular_velocity().tolist(),
    }


@pytest.mark.parametrize('executor', ['events', 'single_threaded'])
def test_generic_client_matches_offline_flight_bit_for_bit(start_node, tmp_path, executor):
    start_node('simulator', '--ros-args', '-p', f'executor_type:={executor}')
    throws = [
        throw_of('pass', Release(alpha0_deg=2.0, alpha_rate_deg_s=10.0)),
        throw_of('kick', Release(ball='rugby', spin_rpm=-300.0, position=(0.0, 1.0, 1.0))),
    ]
    (tmp_path / 'throws.json').write_text(json.dumps(throws))
    out = tmp_path / 'out.json'
    client = HERE / 'generic_sim_client.py'  # imports rclpy and the interfaces only
    proc = subprocess.run(
        [sys.executable, str(client), NODE, str(tmp_path / 'throws.json'), str(out)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    data = json.loads(out.read_text())
    assert sorted(data['spawnables']) == ['football_ros://american', 'football_ros://rugby']
    assert SimulatorFeatures.STEP_SIMULATION_ACTION in data['features']
    assert SimulatorFeatures.SPAWNING_RESOURCE_STRING not in data['features']
    first, second = data['runs']
    assert first == second  # identical calls, identical results: bit for bit (JSON keeps them)
    for throw in throws:
        st = InitialState.from_rigid_body(
            throw['position'], throw['velocity'], throw['orientation'], throw['angular_velocity']
        )
        flight = Flight(get_preset(throw['uri'].split('//')[1]), st, 'paper', 'linear', 0.001)
        for reading in first:
            sample = flight.sample(reading['steps'] * 0.001)
            got = np.array(reading['states'][throw['name']])
            want = np.concatenate(
                (sample.position, sample.orientation, sample.velocity, sample.angular_velocity)
            )
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    assert [r['steps'] for r in first] == [1, 100, 500, 1000, 1700]


def result_of(response):
    return response.result.result, response.result.error_message


def test_every_service_refuses_hostile_values(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'max_entities:=3')
    S = si_srv
    nan = float('nan')

    def spawn(name='a', uri='football_ros://american', pos=(0.0, 0.0, 0.0),
              quat=(0.0, 0.0, 0.0, 1.0), frame='', ns='', rename=False, resource=''):
        request = S.SpawnEntity.Request(
            name=name, uri=uri, allow_renaming=rename, entity_namespace=ns,
            resource_string=resource,
        )
        request.initial_pose = PoseStamped()
        request.initial_pose.header.frame_id = frame
        p, q = request.initial_pose.pose.position, request.initial_pose.pose.orientation
        p.x, p.y, p.z = pos
        q.x, q.y, q.z, q.w = quat
        response = call(collector, S.SpawnEntity, f'{NODE}/spawn_entity', request, 20.0)
        return response.result.result, response.result.error_message, response.entity_name

    R = S.SpawnEntity.Response
    cases = [
        ({'name': ''}, R.NAME_INVALID, 'empty'),
        ({'name': 'bad name!'}, R.NAME_INVALID, 'invalid'),
        ({'name': 'x' * 100}, R.NAME_INVALID, 'invalid'),
        ({'uri': ''}, R.NO_RESOURCE, 'uri'),
        ({'uri': '', 'resource': ' <sdf/>'}, R.UNSUPPORTED_FORMAT, 'resource_string'),
        ({'uri': 'model://ball.sdf'}, R.UNSUPPORTED_FORMAT, 'football_ros://'),
        ({'uri': 'football_ros://soccer'}, NOT_FOUND, 'soccer'),
        ({'pos': (nan, 0.0, 0.0)}, R.INVALID_POSE, 'finite'),
        ({'pos': (0.0, 0.0, -5.0)}, R.INVALID_POSE, 'outside the field'),
        ({'quat': (0.0, 0.0, 0.0, 0.0)}, R.INVALID_POSE, 'unit quaternion'),
        ({'frame': 'map'}, R.INVALID_POSE, 'world frame'),
        ({'ns': 'team1'}, Result.RESULT_FEATURE_UNSUPPORTED, 'namespace'),
    ]
    for kwargs, code, words in cases:
        got, message, _ = spawn(**kwargs)
        assert (got, words in message) == (code, True), (kwargs, got, message)
    assert spawn('a')[0] == OK
    assert spawn('a')[:1] == (R.NAME_NOT_UNIQUE,)
    got, _msg, renamed = spawn('a', rename=True)
    assert got == OK and renamed != 'a'
    got, message, _ = spawn('c')  # football + a + renamed: the limit of 3
    assert got == FAILED and 'limit of 3' in message

    got, _message = result_of(srv(collector, 'delete_entity', S.DeleteEntity, entity='nobody'))
    assert got == NOT_FOUND
    got, message = result_of(srv(collector, 'delete_entity', S.DeleteEntity, entity='football'))
    assert got == FAILED and 'default entity' in message
    for name, srv_type in (('get_entity_state', S.GetEntityState),
                           ('get_entity_info', S.GetEntityInfo)):
        assert result_of(srv(collector, name, srv_type, entity='nobody'))[0] == NOT_FOUND
    info = srv(collector, 'get_entity_info', S.GetEntityInfo, entity='a')
    assert info.result.result == OK and 'american' in list(info.info.tags)

    def set_state(entity='a', pos=(0.0, 0.0, 1.0), v=(20.0, 0.0, 10.0), w=(60.0, 0.0, 0.0),
                  quat=(0.0, 0.0, 0.0, 1.0), frame='field'):
        state = EntityState()
        state.header.frame_id = frame
        state.pose.position.x, state.pose.position.y, state.pose.position.z = pos
        o = state.pose.orientation
        o.x, o.y, o.z, o.w = quat
        state.twist.linear.x, state.twist.linear.y, state.twist.linear.z = v
        state.twist.angular.x, state.twist.angular.y, state.twist.angular.z = w
        return result_of(srv(collector, 'set_entity_state', S.SetEntityState, entity=entity,
                             state=state))

    IP = S.SetEntityState.Response.INVALID_POSE
    assert set_state(entity='nobody')[0] == NOT_FOUND
    assert set_state(pos=(nan, 0.0, 1.0))[0] == IP
    assert set_state(quat=(nan, 0.0, 0.0, 1.0))[0] == IP
    assert set_state(frame='map')[0] == IP
    got, message = set_state(v=(1e300, 0.0, 0.0))
    assert got == FAILED and 'speed' in message, message
    assert set_state(w=(0.0, 0.0, 1e308))[0] == FAILED
    assert set_state(v=(nan, 0.0, 0.0))[0] == FAILED
    assert set_state()[0] == OK  # a 22 m/s throw with spin along the velocity's axis

    # Stepping needs a paused simulation; huge step counts are refused, not attempted.
    got, message = result_of(srv(collector, 'step_simulation', S.StepSimulation, steps=10))
    assert got == FAILED and 'playing' in message
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    assert result_of(srv(collector, 'set_simulation_state', S.SetSimulationState,
                         state=paused))[0] == OK
    assert result_of(srv(collector, 'set_simulation_state', S.SetSimulationState,
                         state=paused))[0] == S.SetSimulationState.Response.ALREADY_IN_TARGET_STATE
    for value, code in ((SimulationState.STATE_QUITTING, UNSUPPORTED), (77, FAILED)):
        assert result_of(srv(collector, 'set_simulation_state', S.SetSimulationState,
                             state=SimulationState(state=value)))[0] == code
    state = srv(collector, 'get_simulation_state', S.GetSimulationState)
    assert state.state.state == SimulationState.STATE_PAUSED
    got, message = result_of(srv(collector, 'step_simulation', S.StepSimulation, steps=2**64 - 1))
    assert got == FAILED and '18446744073709551615' in message
    assert result_of(srv(collector, 'step_simulation', S.StepSimulation, steps=0))[0] == OK

    from rclpy.action import ActionClient

    action = ActionClient(collector.node, SimulateSteps, f'{NODE}/simulate_steps')
    assert action.wait_for_server(timeout_sec=20.0)
    goal = action.send_goal_async(SimulateSteps.Goal(steps=2**64 - 1))
    collector.wait_for(goal.done, 20.0, 'goal accepted')
    done = goal.result().get_result_async()
    collector.wait_for(done.done, 20.0, 'goal result')
    assert done.result().result.result.result == FAILED

    # Filters: bad expressions and unsupported bounds.
    filters = si_srv.GetEntities.Request().filters
    filters.filter = '('
    assert result_of(srv(collector, 'get_entities', S.GetEntities, filters=filters))[0] == FAILED
    filters.filter = '(?=a)'  # lookahead: not in RE2's linear-time syntax
    assert result_of(srv(collector, 'get_entities', S.GetEntities, filters=filters))[0] == FAILED
    filters.filter = ''
    filters.bounds.type = Bounds.TYPE_CONVEX_HULL
    assert result_of(srv(collector, 'get_entities', S.GetEntities, filters=filters))[0] == (
        UNSUPPORTED
    )
    filters.bounds.type = Bounds.TYPE_SPHERE
    from geometry_msgs.msg import Vector3

    filters.bounds.points = [Vector3(x=nan), Vector3(x=1.0)]
    assert result_of(srv(collector, 'get_entities', S.GetEntities, filters=filters))[0] == FAILED
    filters.bounds.points = [Vector3(), Vector3(x=0.5)]
    near = srv(collector, 'get_entities', S.GetEntities, filters=filters)
    # 'a' was thrown (it flies while playing) and has left the sphere; the others rest in it.
    assert near.result.result == OK and list(near.entities) == ['football', renamed]
    assert result_of(srv(collector, 'reset_simulation', S.ResetSimulation, scope=8))[0] == (
        UNSUPPORTED
    )
    # Every state is finite; reset removes the spawned balls.
    states = srv(collector, 'get_entities_states', S.GetEntitiesStates)
    assert states.result.result == OK and len(states.states) == 3
    for s in states.states:
        p, v = s.pose.position, s.twist.linear
        assert all(math.isfinite(x) for x in (p.x, p.y, p.z, v.x, v.y, v.z))
    assert result_of(srv(collector, 'reset_simulation', S.ResetSimulation, scope=0))[0] == OK
    assert list(srv(collector, 'get_entities', S.GetEntities).entities) == ['football']


def test_spawned_ball_flies_in_real_time_on_its_own_topics_and_tf(start_node, collector):
    from diagnostic_msgs.msg import DiagnosticArray
    from football_ros.nodes import qos
    from tf2_msgs.msg import TFMessage

    start_node('simulator', '--ros-args', '-p', 'publish_rate:=200.0')
    collector.subscribe(PoseStamped, 'football/b1/pose', qos.STATE)
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    spawn = si_srv.SpawnEntity.Request(name='b1', uri='football_ros://american')
    answer = call(collector, si_srv.SpawnEntity, f'{NODE}/spawn_entity', spawn, 20.0)
    assert answer.result.result == OK and answer.entity_name == 'b1'
    release = Release(speed=15.0)
    throw = throw_of('b1', release)
    state = EntityState()
    p, o = state.pose.position, state.pose.orientation
    p.x, p.y, p.z = throw['position']
    o.x, o.y, o.z, o.w = throw['orientation']
    v, w = state.twist.linear, state.twist.angular
    v.x, v.y, v.z = throw['velocity']
    w.x, w.y, w.z = throw['angular_velocity']
    assert srv(collector, 'set_entity_state', si_srv.SetEntityState, entity='b1',
               state=state).result.result == OK
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the landed event')
    collector.wait_for(
        lambda: collector.get('football/b1/pose')[-1].pose.position.z == 0.0, 5.0, 'the landing'
    )
    poses = collector.get('football/b1/pose')
    expected = Flight.from_release(release).simulate(rate=200.0, duration=10.0)
    last = poses[-1].pose.position
    np.testing.assert_allclose(
        [last.x, last.y, last.z], expected.positions[-1], rtol=0, atol=1e-9
    )
    assert len(poses) >= len(expected.times) - 1
    frames = {t.child_frame_id for m in collector.get(qos.TF) for t in m.transforms}
    assert 'football/b1' in frames
    state = srv(collector, 'get_entity_state', si_srv.GetEntityState, entity='b1')
    assert state.result.result == OK and state.state.pose.position.z == 0.0
    assert state.state.twist.linear.x == 0.0  # at rest on the ground
