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

"""The planner node with the real nodes, its request language fuzzed, hostile and flood."""

import json
import math
import time

from football_ros.planning import PlanError
from football_ros.planning.request import read_plan_request
from football_ros.requests import read_request, RequestError
from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as hs
import numpy as np
import pytest

JSON = hs.recursive(
    hs.none() | hs.booleans() | hs.integers(-10**6, 10**6) | hs.floats(allow_nan=True)
    | hs.text(max_size=12),
    lambda children: hs.lists(children, max_size=4)
    | hs.dictionaries(hs.text(max_size=10), children, max_size=4),
    max_leaves=12,
)
KEYS = hs.sampled_from(['target', 'receiver', 'arrival_time', 'arrival_window', 'objective',
                        'max_speed', 'elevation_range', 'attitude', 'tolerance', 'catch_radius',
                        'sigmas', 'hit_n', 'execute', 'ball', 'speed', 'spin_rpm', 'position',
                        'model', 'aero', 'id', 'bogus'])


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(hs.dictionaries(KEYS, JSON, max_size=6))
def test_plan_request_reader_refuses_with_plan_errors_only(data):
    try:
        req = read_plan_request(data)
    except PlanError as exc:
        assert str(exc)
        return
    assert ('target' in req.options) != ('receiver' in req.options
                                         or req.receiver_from_odometry)


@settings(max_examples=200, deadline=None, suppress_health_check=list(HealthCheck))
@given(hs.text(max_size=200) | JSON.map(json.dumps))
def test_request_text_reader_then_plan_reader(text):
    try:
        _, keys = read_request(text)
        read_plan_request(keys)
    except (RequestError, PlanError):
        pass


def test_plan_request_fields_named():
    with pytest.raises(PlanError, match='target'):
        read_plan_request({'target': [1, 2]})
    with pytest.raises(PlanError, match='unknown key'):
        read_plan_request({'target': [10, 0, 1], 'speeed': 3})
    with pytest.raises(PlanError, match='execute'):
        read_plan_request({'target': [10, 0, 1], 'execute': 'yes'})
    with pytest.raises(PlanError, match='compare_arcs'):
        read_plan_request({'target': [10, 0, 1], 'compare_arcs': 1})
    with pytest.raises(PlanError, match='hit_n'):
        read_plan_request({'target': [10, 0, 1], 'hit_n': 10**9})
    with pytest.raises(PlanError, match='spin_rpm'):
        read_plan_request({'target': [10, 0, 1], 'spin_rpm': 1e9})
    req = read_plan_request({'receiver': {'position': [20, 0, 1], 'velocity': [0, 3, 0]},
                             'objective': 'flat', 'execute': True})
    assert req.execute and req.options['objective'] == 'flat'


def _answers(collector, topic, request_id):
    return [m for m in collector.get(topic) if m.name == request_id]


def _wait_for_answer(collector, node, request_id, timeout=120.0):
    """Wait for the planner's answer to ``request_id`` (a busy machine: long); else its log."""
    from football_ros.nodes import qos

    try:
        collector.wait_for(lambda: _answers(collector, qos.PLAN_RESPONSE, request_id), timeout,
                           request_id)
    except AssertionError as exc:
        raise AssertionError(f'{exc}; the planner logged:\n{node.log()}') from None


def _values(status):
    return {kv.key: kv.value for kv in status.values}


def test_planned_throw_through_planner_release_and_simulator(start_node, collector):
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from football_ros.nodes import qos
    from nav_msgs.msg import Path
    from std_msgs.msg import String

    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    collector.subscribe(DiagnosticStatus, qos.PLAN_RESPONSE, qos.REQUEST)
    collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
    collector.subscribe(Path, qos.PLAN_PATH, qos.PLAN_PATH_QOS)
    start_node('simulator')
    start_node('release')
    planner = start_node('planner')
    pub = collector.publisher(String, qos.PLAN_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(pub)
    # The planner throws only if it sees a release node (else 'not thrown'): on a busy machine
    # discovery takes a while; wait until the graph shows both ends of the release requests.
    collector.wait_for(
        lambda: collector.node.count_publishers('/' + qos.RELEASE_REQUEST) >= 1
        and collector.node.count_subscribers('/' + qos.RELEASE_REQUEST) >= 1,
        20.0,
        'the planner and the release node on the release requests',
    )
    time.sleep(1.0)  # and the planner's own view of the release node
    target = [31.0, -2.5, 0.0]  # on the ground: the simulator reports its landing point
    request = {'id': 'plan-1', 'target': target, 'model': 'full', 'aero': {'wind': [1, 3, 0]},
               'ball': 'rugby', 'spin_rpm': -300, 'objective': 'flat', 'speed': 24,
               'hit_n': 500, 'execute': True, 'compare_arcs': True}
    pub.publish(String(data=json.dumps(request)))
    _wait_for_answer(collector, planner, 'plan-1')
    answer = _answers(collector, qos.PLAN_RESPONSE, 'plan-1')[0]
    values = _values(answer)
    assert answer.message.startswith('planned: 24.00 m/s'), answer.message
    assert 'sent to the release node' in answer.message, answer.message
    assert float(values['miss_m']) < 0.01
    assert float(values['wobble_deg']) < float(values['aligned_wobble_deg'])
    assert 0.0 <= float(values['hit_probability']) <= 1.0
    assert values['more_robust'] in ('flat', 'lofted', 'either')
    assert float(values['flat_elevation_deg']) < float(values['lofted_elevation_deg'])
    collector.wait_for(lambda: collector.get(qos.PLAN_PATH), 10.0, 'the path')
    path = collector.get(qos.PLAN_PATH)[0]
    last = path.poses[-1].pose.position
    assert path.header.frame_id == 'field' and 10 < len(path.poses) <= 501
    assert math.dist((last.x, last.y, last.z), target) < 0.01
    collector.wait_for(lambda: _answers(collector, qos.RELEASE_RESPONSE, 'plan-1'), 20.0,
                       'the release answer')
    assert _answers(collector, qos.RELEASE_RESPONSE, 'plan-1')[0].message.startswith('accepted')

    def landing():
        for arr in collector.get(qos.DIAGNOSTICS):
            for st in arr.status:
                kv = _values(st)
                if 'landing_x' in kv and 'flight_id' in kv and kv['flight_id'] == 'plan-1':
                    return float(kv['landing_x']), float(kv['landing_y'])
        return None

    collector.wait_for(lambda: landing() is not None, 20.0, 'the landing')
    x, y = landing()
    assert math.hypot(x - target[0], y - target[1]) < 0.01
    assert len(_answers(collector, qos.PLAN_RESPONSE, 'plan-1')) == 1
    # Without an id: answered as req-<n>, thrown under the release id the answer reports.
    pub.publish(String(data=json.dumps({'target': [20.0, 1.0, 0.0], 'hit_n': 0,
                                        'execute': True})))
    collector.wait_for(
        lambda: [m for m in collector.get(qos.PLAN_RESPONSE) if m.name.startswith('req-')],
        30.0, 'the plan without an id')
    plans = [m for m in collector.get(qos.PLAN_RESPONSE) if m.name.startswith('req-')]
    assert len(plans) == 1 and plans[0].message.startswith('planned'), plans
    release_id = _values(plans[0])['release_request_id']
    assert release_id.startswith('plan-') and f"as '{release_id}'" in plans[0].message
    collector.wait_for(lambda: _answers(collector, qos.RELEASE_RESPONSE, release_id), 20.0,
                       'the release answer under the reported id')
    thrown = _answers(collector, qos.RELEASE_RESPONSE, release_id)
    assert len(thrown) == 1 and thrown[0].message.startswith('accepted'), thrown
    assert math.isclose(float(_values(thrown[0])['landing_x']), 20.0, abs_tol=0.05)


def test_hostile_and_infeasible_requests_and_a_flood(start_node, collector):
    from diagnostic_msgs.msg import DiagnosticStatus
    from football_ros.nodes import qos
    from std_msgs.msg import String

    collector.subscribe(DiagnosticStatus, qos.PLAN_RESPONSE, qos.REQUEST)
    planner = start_node('planner', '--ros-args', '-p', 'queue_depth:=2', '-p', 'hit_n:=0')
    pub = collector.publisher(String, qos.PLAN_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(pub)
    cases = {
        'far': ({'target': [400, 0, 1], 'max_speed': 30}, 'max_speed'),
        'below': ({'target': [20, 0, -1]}, 'below the ground'),
        'nan': ('{"id": "nan", "target": [20, NaN, 1]}', None),
        'types': ({'target': 'x'}, "'target'"),
        'unknown': ({'target': [20, 0, 1], 'wobble': 1}, 'unknown key'),
        'spin': ({'target': [20, 0, 1], 'spin_rpm': 1e300}, 'spin_rpm'),
        'odom': ({'receiver': 'odom'}, 'no receiver Odometry'),
    }
    cases['yaml'] = ('{"id": "yaml", "target": !!python/object:os.system [1]}', 'tag')
    for request_id, (body, expected) in cases.items():  # one at a time (the queue holds 2)
        text = body if isinstance(body, str) else json.dumps(dict(body, id=request_id))
        pub.publish(String(data=text))
        _wait_for_answer(collector, planner, request_id)
        answer = _answers(collector, qos.PLAN_RESPONSE, request_id)
        assert len(answer) == 1 and answer[0].message.startswith('refused'), answer
        if expected:
            assert expected in answer[0].message, answer[0].message
    far = _values(_answers(collector, qos.PLAN_RESPONSE, 'far')[0])
    assert far['limit'] == 'max_speed' and 40.0 < float(far['closest_x']) < 120.0
    # A flood: every request answered exactly once, the surplus "busy" at once.
    ids = [f'flood-{i}' for i in range(40)]
    for request_id in ids:
        pub.publish(String(data=json.dumps({'id': request_id, 'target': [25, 1, 1],
                                            'objective': 'lowest_speed'})))
    collector.wait_for(
        lambda: all(_answers(collector, qos.PLAN_RESPONSE, r) for r in ids), 120.0, 'flood')
    counts = [len(_answers(collector, qos.PLAN_RESPONSE, r)) for r in ids]
    assert counts == [1] * len(ids)
    messages = [_answers(collector, qos.PLAN_RESPONSE, r)[0].message for r in ids]
    assert sum(m.startswith('busy') for m in messages) >= 10
    assert sum(m.startswith('planned') for m in messages) >= 2


def test_receiver_followed_on_odometry(start_node, collector):
    from diagnostic_msgs.msg import DiagnosticStatus
    from football_ros.nodes import qos
    from nav_msgs.msg import Odometry
    from std_msgs.msg import String

    collector.subscribe(DiagnosticStatus, qos.PLAN_RESPONSE, qos.REQUEST)
    planner = start_node('planner', '--ros-args', '-p', 'receiver_topic:=receiver/odom', '-p',
                         'hit_n:=0')
    odom_pub = collector.publisher(Odometry, 'receiver/odom', 10)
    pub = collector.publisher(String, qos.PLAN_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(pub)
    collector.wait_for_subscribers(odom_pub)
    odom = Odometry()
    odom.header.frame_id = 'field'
    odom.pose.pose.position.x, odom.pose.pose.position.z = 27.0, 1.3
    odom.twist.twist.linear.y = -4.0
    for i in range(10):  # stamp 0: "now"; sent again until the planner has one
        odom_pub.publish(odom)
        time.sleep(0.2)
        request_id = f'rx-{i}'
        pub.publish(String(data=json.dumps({'id': request_id, 'receiver': 'odom',
                                            'objective': 'flat'})))
        _wait_for_answer(collector, planner, request_id)
        answer = _answers(collector, qos.PLAN_RESPONSE, request_id)[0]
        if answer.message.startswith('planned'):
            break
        assert 'no receiver Odometry' in answer.message
    values = _values(answer)
    t = float(values['arrival_time'])
    point = np.array([float(values[f'arrival_point_{c}']) for c in 'xyz'])
    assert np.linalg.norm(point - np.array([27.0, -4.0 * t, 1.3])) < 0.01
    assert t > 0.5


def test_launch_argument_planner_runs_the_node(monkeypatch):
    import test_launch

    declared, nodes = test_launch.launch(monkeypatch, planner='true')
    assert declared['planner']['default_value'] == 'false'
    assert set(nodes) == {'football_simulator', 'football_release', 'football_planner'}
    assert nodes['football_planner'][0].kwargs['executable'] == 'planner'
