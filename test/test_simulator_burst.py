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
Every call answered: bursts from several clients at once, hostile name filters, frames.

Each service gets a burst of concurrent calls from four clients and must answer every one
(rclpy's default service queue of 10 dropped the rest); 1000 StepSimulation(1) calls must add up
to exactly 1 s of flight; generic clients find the services by type, or at root names.
"""

from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from geometry_msgs.msg import Vector3
import numpy as np
import pytest
from rosutil import call

si_srv = pytest.importorskip('simulation_interfaces.srv')
from simulation_interfaces.action import SimulateSteps  # noqa: E402
from simulation_interfaces.msg import EntityState, Result, SimulationState  # noqa: E402

NODE = '/football_simulator'
OK = Result.RESULT_OK
CLIENTS = 4


def srv(collector, service, srv_type, **fields):
    return call(collector, srv_type, f'{NODE}/{service}', srv_type.Request(**fields),
                timeout=20.0)


def burst(collector, srv_type, name: str, requests: list, timeout: float = 120.0) -> list:
    """Send ``requests`` at once from CLIENTS clients (round robin); return every answer."""
    # Deep response queues on the client side too: a reader 10 deep (rclpy's default) drops
    # the answers it has not taken yet.
    clients = [collector.node.create_client(srv_type, name, qos_profile=qos.service_qos())
               for _ in range(CLIENTS)]
    for client in clients:
        assert client.wait_for_service(timeout_sec=20.0)
    futures = [clients[k % CLIENTS].call_async(r) for k, r in enumerate(requests)]
    try:
        collector.wait_for(lambda: all(f.done() for f in futures), timeout,
                           f'{len(requests)} answers of {name}')
    except AssertionError:
        raise AssertionError(f'{sum(f.done() for f in futures)} of {len(requests)} answered')
    return [f.result() for f in futures]


def throw(collector, name: str, release: Release, frame: str = '') -> None:
    st = release.initial_state()
    state = EntityState()
    state.header.frame_id = frame
    p, o = state.pose.position, state.pose.orientation
    p.x, p.y, p.z = st.position.tolist()
    o.x, o.y, o.z, o.w = st.attitude.tolist()
    v, w = state.twist.linear, state.twist.angular
    v.x, v.y, v.z = st.velocity.tolist()
    w.x, w.y, w.z = st.angular_velocity().tolist()
    answer = srv(collector, 'set_entity_state', si_srv.SetEntityState, entity=name, state=state)
    assert answer.result.result == OK, answer.result.error_message


def test_bursts_of_a_thousand_calls_are_all_answered(start_node, collector):
    S = si_srv
    start_node('simulator', '--ros-args', '-p', 'max_entities:=20')
    assert srv(collector, 'spawn_entity', S.SpawnEntity, name='b0',
               uri='football_ros://american').result.result == OK
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    assert srv(collector, 'set_simulation_state', S.SetSimulationState,
               state=paused).result.result == OK
    release = Release(speed=20.0)
    throw(collector, 'b0', release)

    # 1000 steps of 1 ms from four clients at once: every call answered, exactly 1 s flown.
    steps = burst(collector, S.StepSimulation, f'{NODE}/step_simulation',
                  [S.StepSimulation.Request(steps=1) for _ in range(1000)])
    assert [r.result.result for r in steps] == [OK] * 1000
    state = srv(collector, 'get_entity_state', S.GetEntityState, entity='b0').state
    want = Flight.from_release(release).state_at(1.0)
    got = [state.pose.position.x, state.pose.position.y, state.pose.position.z]
    np.testing.assert_allclose(got, want[:3], rtol=0, atol=1e-9)
    # The model's acceleration in the world frame: the paper model's is gravity alone.
    a = state.acceleration.linear
    assert [a.x, a.y, a.z] == pytest.approx([0.0, 0.0, -9.81], abs=1e-12)
    assert state.header.frame_id == 'field'

    for srv_type, name, request, count in (
        (S.GetSimulationState, 'get_simulation_state', S.GetSimulationState.Request(), 1000),
        (S.GetEntityState, 'get_entity_state', S.GetEntityState.Request(entity='b0'), 1000),
        (S.GetEntityState, 'get_entity_state', S.GetEntityState.Request(entity='nobody'), 300),
        (S.GetEntities, 'get_entities', S.GetEntities.Request(), 300),
        (S.GetEntitiesStates, 'get_entities_states', S.GetEntitiesStates.Request(), 300),
        (S.GetEntityInfo, 'get_entity_info', S.GetEntityInfo.Request(entity='b0'), 300),
        (S.GetEntityBounds, 'get_entity_bounds', S.GetEntityBounds.Request(entity='b0'), 300),
        (S.GetSimulatorFeatures, 'get_simulator_features', S.GetSimulatorFeatures.Request(),
         300),
        (S.GetSpawnables, 'get_spawnables', S.GetSpawnables.Request(), 300),
        (S.SetSimulationState, 'set_simulation_state',
         S.SetSimulationState.Request(state=paused), 300),
        (S.DeleteEntity, 'delete_entity', S.DeleteEntity.Request(entity='nobody'), 300),
    ):
        answers = burst(collector, srv_type, f'{NODE}/{name}', [request] * count)
        assert len(answers) == count, name
        codes = {r.result.result if hasattr(r, 'result') else None for r in answers}
        assert len(codes) == 1, (name, codes)  # the same request, the same one answer
    # Spawn and delete in one burst: 19 names fit (max_entities 20, b0 and football there).
    spawns = [S.SpawnEntity.Request(name=f's{k}', uri='football_ros://rugby') for k in range(300)]
    answers = burst(collector, S.SpawnEntity, f'{NODE}/spawn_entity', spawns)
    codes = [r.result.result for r in answers]
    assert codes.count(OK) == 18 and len(codes) == 300
    listed = srv(collector, 'get_entities', S.GetEntities).entities
    assert len(listed) == 20
    # The node's own services too (pause, reset).
    from std_srvs.srv import SetBool

    answers = burst(collector, SetBool, qos.PAUSE_SERVICE, [SetBool.Request(data=True)] * 500)
    assert all(r.success for r in answers) and len(answers) == 500


def test_hostile_filters_are_answered_and_the_ticks_go_on(start_node, collector):
    from tf2_msgs.msg import TFMessage

    S = si_srv
    start_node('simulator', '--ros-args', '-p', 'max_entities:=40')
    names = ['a' * 60 + f'_{k:02d}' for k in range(30)]
    for name in names:
        assert srv(collector, 'spawn_entity', S.SpawnEntity, name=name,
                   uri='football_ros://american').result.result == OK
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    patterns = ['.*' * 30 + 'X', '.*' * 10 + 'X', '(a+)+$', '(a|aa)+$', '(.*){12}b', 'a{1000}']
    for pattern in patterns:
        filters = S.GetEntities.Request().filters
        filters.filter = pattern
        before = len(collector.get(qos.TF))
        answers = burst(collector, S.GetEntities, f'{NODE}/get_entities',
                        [S.GetEntities.Request(filters=filters)] * 20)
        assert {r.result.result for r in answers} <= {OK, Result.RESULT_OPERATION_FAILED}
        for r in answers:
            assert all(n in names + ['football'] for n in r.entities)
        collector.wait_for(lambda: len(collector.get(qos.TF)) > before + 5, 10.0,
                           'transforms after the filters')  # the pacer was never held


def test_goals_and_cancels_in_bursts_each_get_one_answer(start_node, collector):
    from rclpy.action import ActionClient

    S = si_srv
    start_node('simulator')
    paused = SimulationState(state=SimulationState.STATE_PAUSED)
    assert srv(collector, 'set_simulation_state', S.SetSimulationState,
               state=paused).result.result == OK
    deep = qos.service_qos()  # the clients' answer queues as deep as the server's
    clients = [ActionClient(collector.node, SimulateSteps, f'{NODE}/simulate_steps',
                            goal_service_qos_profile=deep, result_service_qos_profile=deep,
                            cancel_service_qos_profile=deep)
               for _ in range(CLIENTS)]
    for client in clients:
        assert client.wait_for_server(timeout_sec=20.0)
    sent = [clients[k % CLIENTS].send_goal_async(SimulateSteps.Goal(steps=100))
            for k in range(200)]
    collector.wait_for(lambda: all(f.done() for f in sent), 120.0, '200 goal answers')
    accepted = [f.result() for f in sent if f.result().accepted]
    assert accepted  # one at a time: the others refused, each with an answer
    results = [h.get_result_async() for h in accepted]
    collector.wait_for(lambda: all(f.done() for f in results), 120.0, 'the results')
    assert all(f.result().result.result.result == OK for f in results)
    # A long goal and 300 cancel requests for it: every cancel answered.
    long_goal = clients[0].send_goal_async(SimulateSteps.Goal(steps=600_000))
    collector.wait_for(long_goal.done, 20.0, 'the long goal')
    handle = long_goal.result()
    cancels = [handle.cancel_goal_async() for _ in range(300)]
    collector.wait_for(lambda: all(f.done() for f in cancels), 120.0, '300 cancel answers')
    done = handle.get_result_async()
    collector.wait_for(done.done, 60.0, 'the long goal result')
    from action_msgs.msg import GoalStatus

    status, outcome = done.result().status, done.result().result.result
    if status == GoalStatus.STATUS_CANCELED:  # else it had ended before the first cancel
        assert 'canceled after' in outcome.error_message
    else:
        assert status == GoalStatus.STATUS_SUCCEEDED and outcome.result == OK


def test_found_by_type_and_at_root_names_with_entity_frames(start_node, collector):
    S = si_srv
    start_node('simulator', '--ros-args', '-p', 'root_services:=true')
    node = collector.node

    def by_type(type_name: str) -> list[str]:
        return [n for n, types in node.get_service_names_and_types()
                if f'simulation_interfaces/srv/{type_name}' in types]

    collector.wait_for(lambda: len(by_type('SpawnEntity')) == 2, 20.0, 'the services by type')
    assert sorted(by_type('SpawnEntity')) == ['/football_simulator/spawn_entity',
                                              '/spawn_entity']
    features = call(collector, S.GetSimulatorFeatures, by_type('GetSimulatorFeatures')[0],
                    S.GetSimulatorFeatures.Request())
    assert "'world'" in features.features.custom_info
    # Spawned in the world (by its standard name), then relative to that entity's frame.
    request = S.SpawnEntity.Request(name='anchor', uri='football_ros://american')
    request.initial_pose.header.frame_id = 'world'
    p, q = request.initial_pose.pose.position, request.initial_pose.pose.orientation
    p.x, p.y, p.z = 10.0, 5.0, 1.0
    q.z, q.w = np.sin(np.pi / 4), np.cos(np.pi / 4)  # turned 90 deg left
    assert call(collector, S.SpawnEntity, '/spawn_entity', request).result.result == OK
    for frame in ('anchor', 'football/anchor'):
        name = f'rel_{frame.replace("/", "_")}'
        request = S.SpawnEntity.Request(name=name, uri='football_ros://american')
        request.initial_pose.header.frame_id = frame
        request.initial_pose.pose.position.x = 2.0  # 2 m along the anchor's x: world +y
        request.initial_pose.pose.orientation.w = 1.0
        answer = call(collector, S.SpawnEntity, '/spawn_entity', request)
        assert answer.result.result == OK, answer.result.error_message
        state = call(collector, S.GetEntityState, '/get_entity_state',
                     S.GetEntityState.Request(entity=name)).state
        pos = state.pose.position
        assert [pos.x, pos.y, pos.z] == pytest.approx([10.0, 7.0, 1.0], abs=1e-12)
    request = S.SpawnEntity.Request(name='lost', uri='football_ros://american')
    request.initial_pose.header.frame_id = 'nowhere'
    answer = call(collector, S.SpawnEntity, '/spawn_entity', request)
    assert answer.result.result == S.SpawnEntity.Response.INVALID_POSE
    assert "'nowhere'" in answer.result.error_message
    # A twist given in the anchor's frame: its x axis is the world's y.
    state = EntityState()
    state.header.frame_id = 'anchor'
    state.pose.orientation.w = 1.0
    state.pose.position.z = 1.0
    state.twist.linear = Vector3(x=10.0, z=5.0)
    state.twist.angular = Vector3(x=60.0)
    answer = call(collector, S.SetEntityState, '/set_entity_state',
                  S.SetEntityState.Request(entity='rel_anchor', state=state))
    assert answer.result.result == OK, answer.result.error_message
    got = call(collector, S.GetEntityState, '/get_entity_state',
               S.GetEntityState.Request(entity='rel_anchor')).state
    v = got.twist.linear
    if got.pose.position.z > 0.0:  # still in the air (not landed and held at rest)
        assert abs(v.x) < 1.0 and v.y > 5.0


def test_a_handler_due_beside_a_tick_waits_for_it_and_no_longer():
    """TickGate: a handler inside the guard waits for the pacer's next deadline; else not."""
    import threading
    import time

    from football_ros.nodes.simulator import TickGate

    gate = TickGate(guard_s=30.0)  # a guard and a period far longer than any scheduling delay
    period = int(60e9)
    gate.wait_clear()  # not armed (not pacing, or paused): no wait
    gate.announce(time.monotonic_ns() + int(120e9), period)
    gate.wait_clear()  # the tick is beyond the guard: no wait

    def handler(order: list) -> threading.Thread:
        thread = threading.Thread(target=lambda: (gate.wait_clear(), order.append('handler')))
        thread.start()
        return thread

    for release in ('next deadline', None):  # the pacer moves on, or disarms (paused, stopped)
        order = []
        gate.announce(time.monotonic_ns() + int(1e9), period)  # within the guard
        waiting = handler(order)
        waiting.join(timeout=0.5)
        assert waiting.is_alive() and order == []  # it waits (for up to a period: a minute)
        order.append('tick')
        gate.announce(None if release is None else time.monotonic_ns() + int(120e9), period)
        waiting.join(timeout=30.0)
        assert not waiting.is_alive() and order == ['tick', 'handler']
    gate.announce(time.monotonic_ns() - 2 * period, period)  # a stuck pacer: nobody waits on it
    gate.wait_clear()
