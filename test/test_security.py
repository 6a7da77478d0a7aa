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

"""Issue 22: what a stranger on the domain may change (guarded parameters, acknowledgements)."""

from football_ros.nodes.params import GUARD, GUARDS, ParamSpec, with_guards
from football_ros.nodes.reference import node_tables
import pytest
from rcl_interfaces.srv import DescribeParameters, GetParameters, SetParameters
from rclpy.parameter import Parameter
from rosutil import call

NODE_NAMES = {'simulator': 'football_simulator', 'release': 'football_release'}


def _set(collector, node, name, value):
    request = SetParameters.Request(parameters=[Parameter(name, value=value).to_parameter_msg()])
    return call(collector, SetParameters, f'/{node}/set_parameters', request).results[0]


def _get(collector, node, name):
    request = GetParameters.Request(names=[name])
    return call(collector, GetParameters, f'/{node}/get_parameters', request).values[0]


def test_every_row_a_stranger_could_misuse_is_guarded_or_read_only():
    for name, table in node_tables().items():
        for spec in table:
            assert spec.read_only or spec.guard == GUARD, (name, spec.name)
        if any(spec.guard for spec in table):
            assert table[0] is GUARDS[GUARD], name  # the guard is declared and listed first


def test_an_unknown_guard_is_refused_and_with_guards_adds_the_guard_once():
    with pytest.raises(ValueError, match='unknown guard'):
        ParamSpec('x', 1.0, 'x', guard='nope')
    rows = (ParamSpec('a', 1.0, 'a', guard=GUARD), ParamSpec('b', 1.0, 'b', guard=GUARD))
    assert [s.name for s in with_guards(rows)] == [GUARD, 'a', 'b']
    assert with_guards(with_guards(rows)) == with_guards(rows)
    assert with_guards((ParamSpec('c', 1, 'c'),)) == (ParamSpec('c', 1, 'c'),)


# (node, parameter, value a stranger sets: the attacks and a few more)
ATTACKS = [
    ('simulator', 'frame_id', 'map'),
    ('simulator', 'publish_rate', 1.0),
    ('simulator', 'model', 'full'),
    ('simulator', 'observation_rate', 1.0),
    ('release', 'max_request_bytes', 64),
    ('release', 'ack_timeout', 0.1),
    ('release', 'body_frame_id', 'x'),
]


@pytest.mark.parametrize('node', ['simulator', 'release'])
def test_guarded_parameters_are_refused_at_run_time_by_default(node, start_node, collector):
    start_node(node)
    full = NODE_NAMES[node]
    for _, name, value in (a for a in ATTACKS if a[0] == node):
        before = _get(collector, full, name)
        result = _set(collector, full, name, value)
        assert not result.successful and 'read-only' in result.reason, (name, result.reason)
        assert _get(collector, full, name) == before, name
    # The guard itself is start-up only: a stranger cannot open the door.
    result = _set(collector, full, GUARD, True)
    assert not result.successful
    assert _get(collector, full, GUARD).bool_value is False
    described = call(
        collector, DescribeParameters, f'/{full}/describe_parameters',
        DescribeParameters.Request(names=[ATTACKS[0 if node == 'simulator' else 4][1]]),
    ).descriptors[0]
    assert described.read_only
    assert f'{GUARD}:=true' in described.additional_constraints


@pytest.mark.parametrize('node', ['simulator', 'release'])
def test_guarded_parameters_change_when_started_with_the_guard_on(node, start_node, collector):
    start_node(node, '--ros-args', '-p', f'{GUARD}:=true')
    full = NODE_NAMES[node]
    for _, name, value in (a for a in ATTACKS if a[0] == node):
        result = _set(collector, full, name, value)
        assert result.successful, (name, result.reason)
        got = Parameter.from_parameter_msg(_get_msg(collector, full, name)).value
        assert got == value, name
    if node == 'release':  # the 256-character bound still holds for strings
        result = _set(collector, full, 'body_frame_id', 'x' * 257)
        assert not result.successful and '256' in result.reason


def test_the_string_bound_holds_at_run_time_on_a_reconfigurable_simulator(start_node, collector):
    start_node('simulator', '--ros-args', '-p', f'{GUARD}:=true')
    result = _set(collector, 'football_simulator', 'frame_id', 'x' * 257)
    assert not result.successful and '256' in result.reason


def _get_msg(collector, node, name):
    from rcl_interfaces.msg import Parameter as ParameterMsg

    return ParameterMsg(name=name, value=_get(collector, node, name))


# --- acknowledgements: only from a simulator the release node matched ----------------------
def _stranger(collector, hardware_id, level):
    """Make the collector a stranger that acknowledges every flight order it reads at once."""
    from diagnostic_msgs.msg import DiagnosticStatus
    from football_ros.nodes import qos
    from std_msgs.msg import String
    import json

    acks = collector.publisher(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
    collector.forged = []

    def forge(msg):
        order_id = json.loads(msg.data)['order']
        collector.forged.append(order_id)
        acks.publish(
            DiagnosticStatus(level=level, name=order_id, message='forged', hardware_id=hardware_id)
        )

    collector.node.create_subscription(String, qos.FLIGHT_ORDER, forge, qos.ORDER)
    return acks


def _answers(collector, ids, timeout=30.0):
    """Send requests ``ids`` (default release) again until each has an answer; return them."""
    import time

    from diagnostic_msgs.msg import DiagnosticStatus
    from football_ros.nodes import qos
    from std_msgs.msg import String

    if qos.RELEASE_RESPONSE not in collector.messages:
        collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
    requests = collector.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(requests)
    answers = {}
    deadline = time.monotonic() + timeout
    for name in ids:
        while name not in answers and time.monotonic() < deadline:
            requests.publish(String(data=f'{{id: {name}}}'))
            t = time.monotonic() + 3.0
            while time.monotonic() < t and name not in answers:
                for r in collector.get(qos.RELEASE_RESPONSE):
                    answers.setdefault(r.name, r)
                time.sleep(0.02)
    assert set(ids) <= set(answers), answers.keys()
    return [answers[name] for name in ids]


def _level(status):
    return status.level[0] if isinstance(status.level, bytes) else status.level


def test_a_forged_ok_without_simulator_is_not_accepted(start_node, collector):
    release = start_node('release', '--ros-args', '-p', 'ack_patience:=1.0')  # the forger reads
    _stranger(collector, '/football_simulator', b'\x00')  # OK, naming the absent simulator
    for answer in _answers(collector, [f'forged-ok-{k}' for k in range(3)]):
        assert _level(answer) == 2, answer.message
        assert 'no simulator acknowledged' in answer.message
    assert collector.forged  # the stranger did acknowledge every order
    release.wait_for_log('ignored: it names')
    assert 'another participant sent it' in release.log()


def test_a_forged_error_naming_another_node_does_not_refuse_a_real_flight(
    start_node, collector
):
    start_node('simulator')
    release = start_node('release')
    _stranger(collector, '/football_simulator_rival', b'\x02')
    answers = _answers(collector, [f'real-{k}' for k in range(3)])
    for answer in answers:
        assert _level(answer) == 0 and 'accepted' in answer.message, answer.message
        values = {kv.key: kv.value for kv in answer.values}
        assert values['simulator'] == '/football_simulator'
    release.wait_for_log("'/football_simulator_rival', which is not a simulator")


# --- launch: enclaves and the guard -------------------------------------------------------
def test_security_true_starts_every_node_in_its_enclave(monkeypatch, tmp_path):
    from test_launch import CONFIG, launch

    _, nodes = launch(monkeypatch, security='true', tracker='true', record='true')
    enclaves = {name: node.kwargs['ros_arguments'] for name, (node, _) in nodes.items()}
    assert enclaves == {
        f'football_{n}': ['--enclave', f'/football_ros/{n}']
        for n in ('simulator', 'release', 'tracker', 'recorder')
    }
    assert all('additional_env' not in node.kwargs for node, _ in nodes.values())
    _, nodes = launch(monkeypatch, keystore=str(tmp_path))
    node, _ = nodes['football_release']
    assert node.kwargs['ros_arguments'] == ['--enclave', '/football_ros/release']
    assert node.kwargs['additional_env'] == {
        'ROS_SECURITY_KEYSTORE': str(tmp_path),
        'ROS_SECURITY_ENABLE': 'true',
        'ROS_SECURITY_STRATEGY': 'Enforce',
    }
    with pytest.raises(ValueError, match="'keystore'"):
        launch(monkeypatch, keystore=str(tmp_path / 'missing'))
    _, nodes = launch(monkeypatch, allow_reconfigure='true')
    assert nodes['football_simulator'][1] == [str(CONFIG), {'allow_reconfigure': True}]
    assert nodes['football_release'][1][1] == {'use_sim_time': False, 'allow_reconfigure': True}
    _, nodes = launch(monkeypatch)
    assert 'ros_arguments' not in nodes['football_simulator'][0].kwargs


# --- the 1 MB frame_id attack: no way in through parameters --------------------------------
@pytest.mark.parametrize('node, name', [('simulator', 'frame_id'), ('release', 'body_frame_id')])
def test_a_megabyte_frame_id_is_refused_at_start_up(node, name, tmp_path):
    import subprocess
    import sys

    import yaml

    params = tmp_path / 'big.yaml'
    full = {'simulator': 'football_simulator', 'release': 'football_release'}[node]
    params.write_text(yaml.safe_dump({full: {'ros__parameters': {name: 'x' * (1 << 20)}}}))
    proc = subprocess.run(
        [sys.executable, '-m', 'football_ros.cli', node, '--ros-args', '--params-file',
         str(params)],
        capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 2, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert f"'{name}' must be at most 256 characters" in proc.stderr
    assert len(proc.stderr) < 4000  # the value is not echoed back


def test_a_megabyte_frame_id_is_refused_at_run_time(start_node, collector):
    start_node('release', '--ros-args', '-p', f'{GUARD}:=true')
    result = _set(collector, 'football_release', 'body_frame_id', 'x' * (1 << 20))
    assert not result.successful and '256' in result.reason and len(result.reason) < 200
    assert _get(collector, 'football_release', 'body_frame_id').string_value == 'football'
    start_node('simulator')
    result = _set(collector, 'football_simulator', 'frame_id', 'x' * (1 << 20))
    assert not result.successful and 'read-only' in result.reason


# --- log lines under a flood -----------------------------------------------------------------
def test_the_log_budget_allows_a_burst_a_second_and_counts_the_rest():
    from football_ros.nodes.release import LogBudget

    now = [100.2]
    budget = LogBudget(3, clock=lambda: now[0])
    assert [budget.take() for _ in range(5)] == [(True, 0)] * 3 + [(False, 0)] * 2
    now[0] = 101.0
    assert budget.take() == (True, 2)  # the next line says how many were not logged
    assert budget.take() == (True, 0)


def test_a_flood_of_bad_requests_logs_a_bounded_number_of_lines(start_node, collector):
    import time

    from diagnostic_msgs.msg import DiagnosticStatus
    from football_ros.nodes import qos
    from football_ros.nodes.release import LOG_LINES_PER_S
    from std_msgs.msg import String

    release = start_node('release')
    collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
    requests = collector.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(requests)
    before = release.log().count('\n')
    t0 = time.monotonic()
    for k in range(600):
        requests.publish(String(data=f'{{id: bad-{k}, speed: -1}}'))
        time.sleep(0.002)
    collector.wait_for(lambda: len(collector.get(qos.RELEASE_RESPONSE)) >= 600, 30.0, 'answers')
    seconds = time.monotonic() - t0
    lines = release.log().count('\n') - before
    assert all(_level(r) == 2 for r in collector.get(qos.RELEASE_RESPONSE))  # each answered
    assert lines <= LOG_LINES_PER_S * (seconds + 2), (lines, seconds)
    assert 'were not logged: flood' in release.log()


def test_an_acknowledgement_with_an_unknown_level_is_ignored(start_node, collector):
    start_node('simulator')
    release = start_node('release')
    _stranger(collector, '/football_simulator', b'\xbd')  # names the real simulator
    for answer in _answers(collector, [f'odd-level-{k}' for k in range(3)]):
        assert _level(answer) == 0 and 'accepted' in answer.message, answer.message
    assert collector.forged
    assert 'Traceback' not in release.log() and 'internal error' not in release.log()
