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

"""Release node across processes: contract, bad input on the wire, the state path, floods."""

from collections import Counter
import json
import math
from pathlib import Path
import re
import signal
import time

from diagnostic_msgs.msg import DiagnosticStatus
from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from football_ros.physics.frames import quaternion_to_matrix
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosutil import resend_until
from std_msgs.msg import String

OK, WARN, ERROR = 0, 1, 2  # DiagnosticStatus levels (bytes in rclpy, compared as ints)
REQUIRED_VALUES = {
    'omega_fast',
    'omega_slow',
    'critical_spin_rpm',
    'equilibrium_sideslip',
    'stable',
    'time_of_flight',
    'range',
}


def level(status):
    return status.level[0] if isinstance(status.level, bytes) else status.level


def values(status):
    return {kv.key: kv.value for kv in status.values}


# The test client keeps every answer even when this (loaded) process falls seconds behind a flood.
CLIENT_RESPONSES = QoSProfile(depth=20000, reliability=ReliabilityPolicy.RELIABLE)


@pytest.fixture
def client(collector):
    collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, CLIENT_RESPONSES)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.requests = collector.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
    collector.states = collector.publisher(Odometry, qos.RELEASE_STATE, qos.REQUEST)
    return collector


def ask(client, texts, timeout=20.0):
    """Publish request texts; return the responses that arrive for them (in arrival order)."""
    client.wait_for_subscribers(client.requests)
    before = len(client.get(qos.RELEASE_RESPONSE))
    for text in texts:
        client.requests.publish(String(data=text))
    client.wait_for(
        lambda: len(client.get(qos.RELEASE_RESPONSE)) >= before + len(texts),
        timeout,
        f'{len(texts)} responses',
    )
    time.sleep(0.2)  # anything extra would show up now
    return client.get(qos.RELEASE_RESPONSE)[before:]


def connect(client, timeout=30.0):
    """
    Probe until the release node accepts (it has discovered the simulator); drop the probes.

    Right after start-up DDS discovery may still drop a request (or the release node may not
    see the simulator yet), so a probe without an OK answer is sent again.
    """
    client.wait_for_subscribers(client.requests)

    def accepted():
        return any(r.name.startswith('probe-') and level(r) == OK
                   for r in client.get(qos.RELEASE_RESPONSE))

    resend_until(
        client,
        lambda k: client.requests.publish(String(data=f'{{id: probe-{k}}}')),
        accepted,
        'accepted probe',
        tries=max(1, int(timeout / 2.0)),
    )
    client.wait_for(lambda: client.get(qos.POSE), 10.0, 'the probe flight')
    time.sleep(0.3)  # late answers to earlier probes
    client.clear()


def test_accepted_request_flies_and_answers_with_the_prediction(start_node, client):
    start_node('simulator')
    start_node('release')
    connect(client)
    [resp] = ask(client, ['{id: pass-1, ball: american, speed: 25, spin_rpm: 650}'])
    assert resp.name == 'pass-1' and level(resp) == OK and 'accepted' in resp.message
    vals = values(resp)
    assert REQUIRED_VALUES <= set(vals)
    expected = Flight.from_release(Release(speed=25.0, spin_rpm=650.0))
    assert float(vals['omega_fast']) == pytest.approx(expected.modes.omega_fast, rel=1e-12)
    assert float(vals['time_of_flight']) == pytest.approx(2 * 25 * 0.5 / 9.81, abs=1e-9)
    assert float(vals['range']) == pytest.approx(
        25**2 * math.sin(math.radians(60)) / 9.81, abs=1e-6
    )
    assert vals['stable'] == 'true'
    client.wait_for(lambda: len(client.get(qos.POSE)) > 10, 10.0, "the simulator's poses")
    # Gyroscopically unstable release: accepted with WARN.
    [warn] = ask(client, ['{"id": "slow-spin", "spin_rpm": 200}'])
    assert level(warn) == WARN and 'unstable' in warn.message and values(warn)['stable'] == 'false'


def test_without_simulator_the_answer_says_so(start_node, client):
    start_node('release')
    client.wait_for_subscribers(client.requests)
    resend_until(
        client,
        lambda k: client.requests.publish(String(data=f'{{id: lonely-{k}}}')),
        lambda: client.get(qos.RELEASE_RESPONSE),
        'answer',
    )
    resp = client.get(qos.RELEASE_RESPONSE)[0]
    assert resp.name.startswith('lonely-') and level(resp) == ERROR
    assert 'no simulator is listening' in resp.message


BAD_REQUESTS = [
    ('{id: b1, speed: .nan}', 'b1', 'must be a number'),
    ('{id: b2, speed: -1e999}', 'b2', 'finite'),
    ('{id: b3, speed: -12}', 'b3', 'outside'),
    ('{id: b4, speed: 3000}', 'b4', 'outside'),
    ('{id: b5, spin_rpm: 1e7}', 'b5', 'outside'),
    ('{id: b6, alpha0_deg: 170}', 'b6', 'outside'),
    ('{id: b7, ball: basketball}', 'b7', 'unknown ball preset'),
    ('{id: b8, sped: 20}', 'b8', 'unknown key'),
    ("{id: b9, speed: '20'}", 'b9', 'must be a number'),
    ('{id: b10, position: [0, 0, -3]}', 'b10', 'outside'),
    ('{id: b11, model: full, aero: {c_d0: -1}}', 'b11', 'outside'),
    ('{id: b12, aero: {drag: false}}', 'b12', 'need model: full'),
    ('{id: [oops', None, 'malformed'),
    ('[1, 2, 3]', None, 'mapping'),
    ("!!python/object/apply:os.system ['echo pwned']", None, 'tags'),
    ('{id: b13, speed: 0x14}', 'b13', 'must be a number'),
    ('{id: b14, speed: 20, speed: 21}', 'b14', 'duplicate key'),
    ('{id: b15, aero: {wind: [[[[1]]]]}}', 'b15', 'nested'),
    ('{id: b16, spin_rpm: ' + '9' * 400 + '}', 'b16', 'digits'),
    ("{id: b17, ball: '" + 'x' * 50000 + "'}", 'b17', 'unknown ball preset'),
    ('{id: b18, alpha0_deg: 50, beta0_deg: 50}', 'b18', 'axis offset'),
    ('{id: b19, ball_params: {inertia_spin: 1e-300}}', 'b19', 'inertia_spin'),
    (
        '{id: b20, speed: 20, elevation_deg: 0, position: [0, 0, 2], model: full, '
        'aero: {wind: [20, 0, 0]}}',
        'b20',
        'moves with the wind',
    ),
    (
        '{id: b21, spin_rpm: 3000, model: full, aero: {c_m_q: -100}, '
        'ball_params: {diameter: 0.4, mass: 2}}',
        'b21',
        'step',
    ),
    ('a: &a [1]\nb: *a', None, 'aliases'),
    ('x' * 100000, None, 'bytes'),
]


def test_each_bad_input_class_gets_one_error_and_nothing_else_changes(start_node, client):
    simulator = start_node('simulator')
    release = start_node('release')
    connect(client)
    flights_before = simulator.log().count('released at')
    responses = ask(client, [text for text, _, _ in BAD_REQUESTS])
    assert len(responses) == len(BAD_REQUESTS)
    # Requests that cannot be read are answered at once and in order (under made-up ids); the
    # others are judged by the worker, so they are matched by id.
    by_id = {r.name: r for r in responses}
    made_up = iter([r for r in responses if r.name.startswith('req-')])
    for text, rid, reason in BAD_REQUESTS:
        resp = by_id[rid] if rid else next(made_up)
        assert level(resp) == ERROR, (text[:40], resp.message)
        assert reason in resp.message, (text[:40], resp.message)
        assert len(resp.message) <= 420 and 'internal error' not in resp.message
        assert resp.name == rid if rid else resp.name.startswith('req-')
    assert simulator.log().count('released at') == flights_before  # no flight was started
    log = release.log()
    assert log.count('rejected') >= len(BAD_REQUESTS) and 'Traceback' not in log
    assert not Path('pwned').exists()
    [good] = ask(client, ['{id: after}'])
    assert level(good) == OK


def _state_request(release: Release, sec: int, child: str = 'football') -> Odometry:
    """
    Build the release as an Odometry.

    Twist in the body frame (child ``football``) or, for child ``field``, in the field frame.
    """
    st = release.initial_state()
    msg = Odometry(child_frame_id=child)
    msg.header.frame_id = 'field'
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, 5
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = map(float, st.position)
    q.x, q.y, q.z, q.w = map(float, st.attitude)
    to_twist = np.eye(3) if child == 'field' else quaternion_to_matrix(st.attitude).T
    lin, ang = msg.twist.twist.linear, msg.twist.twist.angular
    lin.x, lin.y, lin.z = map(float, to_twist @ st.velocity)
    ang.x, ang.y, ang.z = map(float, to_twist @ st.angular_velocity())
    return msg


def test_typed_state_request(start_node, client):
    """
    Any Odometry of the ball is a release.

    Body-frame twist (the simulator's own odom fed back included) or field-frame twist; the
    preset comes from the state_ball parameter.
    """
    start_node('simulator')
    start_node('release', '--ros-args', '-p', 'state_ball:=rugby')
    connect(client)
    client.subscribe(Odometry, qos.ODOM, qos.STATE)
    client.wait_for_subscribers(client.states)
    release = Release(ball='rugby', alpha0_deg=2.0, beta_rate_deg_s=-15.0)
    client.states.publish(_state_request(release, 42))
    client.states.publish(_state_request(release, 45, 'field'))
    bad = _state_request(release, 43)
    bad.twist.twist.linear.x = math.nan
    client.states.publish(bad)
    client.states.publish(_state_request(release, 44, 'frisbee'))
    client.wait_for(lambda: len(client.get(qos.RELEASE_RESPONSE)) >= 4, 10.0, '4 responses')
    by_id = {r.name: r for r in client.get(qos.RELEASE_RESPONSE)}
    expected = Flight.from_release(release)
    for name in ('state:42.000000005', 'state:45.000000005'):
        ok = by_id[name]
        assert level(ok) == OK, ok.message
        assert float(values(ok)['equilibrium_sideslip']) == pytest.approx(
            expected.modes.equilibrium_sideslip, rel=1e-9
        )
        assert float(values(ok)['omega_slow']) == pytest.approx(
            expected.modes.omega_slow, rel=1e-9
        )
    assert (
        level(by_id['state:43.000000005']) == ERROR
        and 'finite' in by_id['state:43.000000005'].message
    )
    assert (
        level(by_id['state:44.000000005']) == ERROR
        and 'child_frame_id' in by_id['state:44.000000005'].message
    )
    # The simulator's own odometry, fed back, starts the same flight from that instant.
    client.wait_for(lambda: len(client.get(qos.ODOM)) > 20, 10.0, 'odometry')
    odom = client.get(qos.ODOM)[20]
    odom.header.stamp.sec, odom.header.stamp.nanosec = 46, 5
    client.states.publish(odom)
    client.wait_for(
        lambda: any(r.name == 'state:46.000000005' for r in client.get(qos.RELEASE_RESPONSE)),
        10.0,
        "the fed-back odometry's answer",
    )
    [fed] = [r for r in client.get(qos.RELEASE_RESPONSE) if r.name == 'state:46.000000005']
    assert level(fed) == OK, fed.message
    # The paper model has no drag: x = vx t gives the odometry's flight time.
    t = odom.pose.pose.position.x / release.initial_state().velocity[0]
    full = expected.simulate()
    assert float(values(fed)['time_of_flight']) == pytest.approx(full.times[-1] - t, abs=1e-6)
    assert float(values(fed)['landing_x']) == pytest.approx(full.positions[-1, 0], abs=1e-5)
    assert float(values(fed)['landing_y']) == pytest.approx(full.positions[-1, 1], abs=1e-5)


def _rss_kb(pid: int) -> int:
    for line in Path(f'/proc/{pid}/status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1])
    raise AssertionError('no VmRSS')


@pytest.mark.parametrize('publishers', [1, 10])
def test_flood_every_request_answered_once_memory_bounded(start_node, client, publishers):
    """
    1000 requests/s for 10 s (one publisher, or ten in parallel), a third of them invalid.

    Every request the node reads gets exactly one answer (served, refused or busy); the others
    are the ones DDS reports lost to the node's reader (the clients' KEEP_LAST writers overwrote
    them while this loaded machine fell behind: the request benchmark), so nothing goes
    missing without a word. Memory stays bounded, and the node answers at once afterwards.
    """
    start_node('simulator')
    release = start_node('release')
    connect(client)
    pubs = [client.requests] + [
        client.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST) for _ in range(publishers - 1)
    ]
    for pub in pubs:
        client.wait_for_subscribers(pub)
    time.sleep(
        1.0
    )  # the release node discovers the new writers too (else it drops their first data)
    rss_before = _rss_kb(release.pid)
    rate, seconds = 1000, 10.0
    sent, invalid = [], set()
    start = time.monotonic()
    for k in range(int(rate * seconds)):
        rid = f'flood-{k}'
        if k % 3:
            text = json.dumps({'id': rid, 'speed': 15 + k % 20, 'spin_rpm': 300 + k % 500})
        else:
            text, _ = f'{{id: {rid}, speed: -{k}}}', invalid.add(rid)
        pubs[k % publishers].publish(String(data=text))
        sent.append(rid)
        time.sleep(max(0.0, start + (k + 1) / rate - time.monotonic()))
    # Every answer delivered: none for 5 s (the node answers a read request within its queue).
    client.wait_for(
        lambda: time.monotonic_ns() - client.arrivals[qos.RELEASE_RESPONSE][-1] > 5e9,
        300.0, 'the last answer',
    )
    [after] = ask(client, ['{id: still-there}'])
    assert level(after) == OK
    growth_mb = (_rss_kb(release.pid) - rss_before) / 1024
    assert growth_mb < 30, f'release node grew by {growth_mb:.1f} MB during the flood'
    answers = [r for r in client.get(qos.RELEASE_RESPONSE) if r.name.startswith('flood-')]
    names = Counter(r.name for r in answers)
    release.stop()
    [line] = [x for x in release.log().splitlines() if x.startswith('[release] ')]
    lost = int(re.search(r'(\d+) lost on the way', line).group(1))
    assert set(names) <= set(sent) and set(names.values()) == {1}, line
    # The answers this client's reader lost (reported by DDS: the node's KEEP_LAST writer
    # overwrote them while this loaded process fell behind) were answers all the same.
    lost_answers = client.lost[qos.RELEASE_RESPONSE]
    assert len(names) + lost_answers + lost >= len(sent), (
        f'{len(sent) - len(names)} unanswered, {lost_answers} answers lost on the way; {line}'
    )
    busy = [r for r in answers if values(r).get('busy') == 'true']
    served = [r for r in answers if values(r).get('busy') != 'true']
    assert all(level(r) == ERROR and 'busy' in r.message for r in busy)
    for r in served:  # every request the node took up is judged on its own
        assert (level(r) == ERROR) == (r.name in invalid), (r.name, r.message)
    accepted = [r for r in served if level(r) != ERROR]
    assert len(accepted) > 100, f'only {len(accepted)} of {len(sent)} requests were flown'
    print(
        f'\nflood {rate}/s x {seconds:g} s, {publishers} publisher(s): {len(accepted)} flown, '
        f'{len(served) - len(accepted)} refused, {len(busy)} busy, {lost} reported lost by DDS, '
        f'{lost_answers} answers lost by DDS'
    )


def test_a_killed_simulator_is_reported_within_a_second(start_node, client):
    simulator = start_node('simulator')
    start_node('release', '--ros-args', '-p', 'ack_patience:=1.0')  # DDS still matches it
    connect(client)
    simulator.stop(signal.SIGKILL)
    t0 = time.monotonic()
    [answer] = ask(client, ['{id: into-the-void}'])
    elapsed = time.monotonic() - t0
    assert level(answer) == ERROR and 'no simulator acknowledged' in answer.message
    assert elapsed < 2.0, f'the dead simulator was reported after {elapsed:.2f} s'


HOSTILE_ORDERS = [
    ('[' * 5000 + ']' * 5000, 'unknown', 'nest'),
    (
        '{"id": "h1", "position": [0, 0, 1e999], "velocity": [1, 0, 1], '
        '"orientation": [0, 0, 0, 1], "angular_velocity": [0, 0, 0]}',
        'h1',
        'finite',
    ),
    (
        '{"id": "h2", "position": [0, 0, 1], "velocity": ['
        + '9' * 400
        + ', 0, 1], "orientation": [0, 0, 0, 1], '
        '"angular_velocity": [0, 0, 0]}',
        'h2',
        'digits',
    ),
    (
        '{"id": "h3", "order": "o-h3", "position": [0, 0, 1], "velocity": [20, 0, 10], '
        '"orientation": [0, 0, 0, 1], "angular_velocity": [0, 0, 0], "ball_params": {"mass": 0}}',
        'o-h3',
        'mass',
    ),
    (
        '{"id": "h4", "position": [0, 0, 1], "velocity": [20, 0, 10], '
        '"orientation": [0, 0, 0, 0], "angular_velocity": [0, 0, 0]}',
        'h4',
        'quaternion',
    ),
    ('{"id": "h5", "extra": 1}', 'h5', 'unknown flight-order key'),
    ('not json at all', 'unknown', 'JSON object'),
    ('{"id": "h6", "id": "h7"}', 'h6', 'duplicate'),
]


def test_hostile_flight_orders_are_refused_with_an_acknowledgement(start_node, collector):
    """
    Any participant can publish on football/flight/order.

    Each order gets one ERROR acknowledgement naming the problem, the simulator keeps running
    and flies nothing.
    """
    simulator = start_node('simulator')
    collector.subscribe(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    pub = collector.publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
    collector.wait_for_subscribers(pub)
    time.sleep(0.5)  # the simulator's acknowledgement writer discovers us too
    for text, _, _ in HOSTILE_ORDERS:
        pub.publish(String(data=text))
    collector.wait_for(
        lambda: len(collector.get(qos.FLIGHT_ACK)) >= len(HOSTILE_ORDERS), 10.0, 'acks'
    )
    time.sleep(0.3)
    acks = collector.get(qos.FLIGHT_ACK)
    assert len(acks) == len(HOSTILE_ORDERS)
    for (text, name, reason), ack in zip(HOSTILE_ORDERS, acks):
        assert level(ack) == ERROR and ack.name == name and reason in ack.message, (text[:40], ack)
        assert len(ack.message) <= 400
    assert not collector.get(qos.POSE) and simulator.proc.poll() is None
    assert 'Traceback' not in simulator.log()


def test_two_simulators_are_noticed_by_the_release_node(start_node, client):
    start_node('simulator')
    start_node('simulator')
    release = start_node('release')
    client.wait_for(
        lambda: client.node.count_subscribers(qos.FLIGHT_ORDER) >= 2, 20.0, 'two simulators'
    )
    connect(client)
    for k in range(10):  # until the release node has discovered both simulators
        ask(client, [f'{{id: seen-by-two-{k}}}'])
        if 'more than one simulator listens' in release.log():
            return
        time.sleep(0.5)
    raise AssertionError(f'no warning about two simulators:\n{release.log()}')
