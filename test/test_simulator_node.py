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

"""Simulator node across processes: types, frames, stamps, rate, physics agreement, services."""

import math
import os
import signal
import subprocess
import sys
import time

from cli_run import run_cli
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from football_ros.nodes import qos
from football_ros.nodes.topics import STATE_TOPICS
from football_ros.physics import Flight, Release
from football_ros.physics.frames import quaternion_to_matrix
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rosgraph_msgs.msg import Clock
from rosutil import call, landed_event, order_flight, resend_until
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

STATE_TYPES = STATE_TOPICS


def stamp_ns(msg):
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def subscribe_all(collector):
    for topic, msg_type in STATE_TYPES.items():
        collector.subscribe(msg_type, topic, qos.STATE)
    collector.subscribe(MarkerArray, qos.MARKERS, qos.MARKERS_QOS)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)


def test_flight_on_all_topics_matches_headless_simulation(start_node, collector, tmp_path):
    rate = 200.0
    start_node('simulator', '--ros-args', '-p', f'publish_rate:={rate}', '-p', 'marker_rate:=20.0')
    subscribe_all(collector)
    release = Release(alpha0_deg=2.0, beta0_deg=-1.0, alpha_rate_deg_s=10.0)
    order_flight(collector, release, 'topics-1')
    collector.wait_for(lambda: landed_event(collector), 15.0, 'the landing event')
    expected = Flight.from_release(release).simulate(rate=rate, duration=10.0)
    # Every tick, landing included, on every topic (they may trail the event on a busy machine).
    collector.wait_for(
        lambda: all(len(collector.get(t)) >= len(expected.times) for t in STATE_TYPES),
        20.0, 'every tick on every topic',
    )
    msgs = {topic: collector.get(topic)[:len(expected.times)] for topic in STATE_TYPES}
    # Same stamp on every topic for each tick; stamps exactly 1/rate apart.
    stamps = np.array([[stamp_ns(m) for m in msgs[t]] for t in STATE_TYPES])
    assert np.all(stamps == stamps[0])
    steps = np.diff(stamps[0])
    assert np.all(np.abs(steps - 1e9 / rate) <= 1), steps
    # Frames.
    for topic in (qos.POSE, qos.ODOM, qos.SPIN_AXIS):
        assert all(m.header.frame_id == 'field' for m in msgs[topic])
    for topic in (
        qos.AERO_ANGLES,
        qos.AERO_ANGLES_LINEAR,
        qos.AERO_ANGLES_QUASI_STEADY,
    ):  # no frame
        assert all(m.header.frame_id == '' for m in msgs[topic])
    assert all(m.child_frame_id == 'football' for m in msgs[qos.ODOM])
    # alpha/beta/delta and the linear prediction equal the headless run, sample by sample.
    aero = np.array([[m.vector.x, m.vector.y, m.vector.z] for m in msgs[qos.AERO_ANGLES]])
    assert np.max(np.abs(aero[:-1] - expected.aero_angles[:-1])) < 1e-9
    assert np.max(np.abs(aero[-1] - expected.aero_angles[-1])) < 1e-6  # landing row
    linear = np.array([[m.vector.x, m.vector.y, m.vector.z] for m in msgs[qos.AERO_ANGLES_LINEAR]])
    assert np.max(np.abs(linear[:, :2] - expected.aero_angles_linear)) < 1e-6
    # The linear delta is the angle between the predicted axis and the velocity: for the
    # integrated flight the same formula reproduces its delta, so it is checked on both.
    lin_delta = np.arccos(
        np.cos(expected.aero_angles_linear[:, 0]) * np.cos(expected.aero_angles_linear[:, 1])
    )
    assert np.all(np.isfinite(linear)) and np.max(np.abs(linear[:, 2] - lin_delta)) < 1e-6
    quasi = np.array(
        [[m.vector.x, m.vector.y, m.vector.z] for m in msgs[qos.AERO_ANGLES_QUASI_STEADY]]
    )
    assert np.max(np.abs(quasi[:, :2] - expected.aero_angles_quasi_steady)) < 1e-6
    nonlin_delta = np.arccos(np.cos(aero[:, 0]) * np.cos(aero[:, 1]))
    assert np.max(np.abs(nonlin_delta - aero[:, 2])) < 1e-6
    pos = np.array(
        [[m.pose.position.x, m.pose.position.y, m.pose.position.z] for m in msgs[qos.POSE]]
    )
    assert np.max(np.abs(pos - expected.positions)) < 1e-6 and pos[-1, 2] == 0.0
    axis = np.array([[m.vector.x, m.vector.y, m.vector.z] for m in msgs[qos.SPIN_AXIS]])
    assert np.allclose(np.linalg.norm(axis, axis=1), 1.0, atol=1e-12)
    # Pose orientation: body x is the spin axis. Odometry twist is in the body frame.
    q = np.array(
        [
            [
                m.pose.orientation.x,
                m.pose.orientation.y,
                m.pose.orientation.z,
                m.pose.orientation.w,
            ]
            for m in msgs[qos.POSE]
        ]
    )
    assert np.allclose(quaternion_to_matrix(q)[:, :, 0], axis, atol=1e-9)
    odom = msgs[qos.ODOM][len(pos) // 2]
    v_body = np.array(
        [odom.twist.twist.linear.x, odom.twist.twist.linear.y, odom.twist.twist.linear.z]
    )
    w_body = np.array(
        [odom.twist.twist.angular.x, odom.twist.twist.angular.y, odom.twist.twist.angular.z]
    )
    assert np.linalg.norm(v_body) == pytest.approx(
        np.linalg.norm(expected.velocities[len(pos) // 2]), rel=1e-9
    )
    assert w_body[0] == pytest.approx(600 * 2 * math.pi / 60, rel=1e-9)  # spin p about body x
    # Markers: ball, axis, velocity and trail; diagnostics: released and landed events.
    markers = collector.get(qos.MARKERS)
    assert markers and [mk.type for mk in markers[-1].markers] == [2, 0, 0, 4]
    assert 1 < len(markers) < len(pos)  # throttled to marker_rate
    events = [
        kv.value
        for arr in collector.get(qos.DIAGNOSTICS)
        for s in arr.status
        for kv in s.values
        if kv.key == 'event'
    ]
    assert 'released' in events and 'landed' in events
    landed = [
        s for arr in collector.get(qos.DIAGNOSTICS) for s in arr.status if 'landed at' in s.message
    ]
    assert f'x = {expected.positions[-1, 0]:.3f} m' in landed[0].message


def test_rate_real_time_and_hold_after_landing(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'publish_rate:=500.0', '-p', 'hold_rate:=5.0')
    collector.subscribe(Vector3Stamped, qos.AERO_ANGLES, qos.STATE)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    order_flight(collector, Release(ball='rugby'), 'rate-1')
    collector.wait_for(lambda: landed_event(collector), 15.0, 'the landing event')
    landing = Flight.from_release(Release(ball='rugby')).simulate(rate=500.0)
    n_landed = len(landing.times)
    collector.wait_for(lambda: len(collector.get(qos.AERO_ANGLES)) >= n_landed, 20.0, 'the flight')
    stamps = [stamp_ns(m) for m in collector.get(qos.AERO_ANGLES)[:n_landed]]
    # One tick per 1/500 s of wall time for 1/500 s of flight (real-time factor 1): the stamps
    # are the ticks' deadlines, whole periods apart (a stall of over a second skips ticks).
    periods = np.diff(stamps) / 2_000_000
    assert np.all(periods >= 1) and np.allclose(periods, np.round(periods), rtol=0, atol=1e-6)
    collector.wait_for(lambda: len(collector.get(qos.AERO_ANGLES)) >= n_landed + 4, 20.0,
                       'held states')
    msgs = collector.get(qos.AERO_ANGLES)
    first = len(msgs) - 1  # the landing: the first of the trailing equal states
    while first > 0 and msgs[first - 1].vector == msgs[-1].vector:
        first -= 1
    gaps = np.diff([stamp_ns(m) for m in msgs[first:]])
    # Held at 5 Hz of the tick deadlines: 100 ticks of 2 ms apart (more if a stall skipped).
    assert len(gaps) >= 3 and np.all(gaps >= 200_000_000), gaps
    assert np.median(gaps) == 200_000_000, gaps


def test_real_time_factor_and_clock(start_node, collector):
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_rate:=100.0',
        '-p',
        'real_time_factor:=4.0',
        '-p',
        'publish_clock:=true',
    )
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.subscribe(Clock, qos.CLOCK, qos.CLOCK_QOS)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    order_flight(collector, Release(), 'rtf-1')
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the landing event')
    poses = collector.get(qos.POSE)
    arrivals = collector.arrivals[qos.POSE][: len(poses)]
    # 2.793 s of flight in about 0.7 s of wall time; stamps are simulated time (4 x 10 ms apart).
    assert (arrivals[-1] - arrivals[0]) * 1e-9 == pytest.approx(2.793 / 4, abs=0.1)
    assert np.median(np.diff([stamp_ns(p) for p in poses])) == pytest.approx(40e6, abs=1)
    clocks = collector.get(qos.CLOCK)
    assert clocks and clocks[-1].clock.sec * 1e9 + clocks[-1].clock.nanosec >= stamp_ns(poses[-1])


def test_reset_and_pause_services(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'publish_rate:=100.0', '-p', 'hold_rate:=0.0')
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    nothing = call(collector, Trigger, qos.RESET_SERVICE, Trigger.Request())
    assert not nothing.success and 'nothing was released' in nothing.message
    order_flight(collector, Release(), 'svc-1')
    collector.wait_for(lambda: len(collector.get(qos.POSE)) > 20, 10.0, 'poses')
    assert call(collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=True)).success
    time.sleep(0.2)
    frozen = len(collector.get(qos.POSE))
    time.sleep(0.5)
    assert len(collector.get(qos.POSE)) == frozen
    assert call(collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=False)).success
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the landing event')
    flown = len(collector.get(qos.POSE))
    assert flown == 281  # pausing did not skip or repeat samples: 2.793 s at 100 Hz + landing
    collector.clear()
    again = call(collector, Trigger, qos.RESET_SERVICE, Trigger.Request())
    assert again.success and 'svc-1' in again.message
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the second landing')
    poses = collector.get(qos.POSE)
    assert len(poses) == 281 and poses[0].pose.position.x == 0.0


def test_parameters_have_ranges_and_live_changes_are_validated(start_node, collector):
    from rcl_interfaces.srv import DescribeParameters, SetParameters
    from rclpy.parameter import Parameter

    start_node('simulator', '--ros-args', '-p', 'allow_reconfigure:=true')
    desc = call(
        collector,
        DescribeParameters,
        '/football_simulator/describe_parameters',
        DescribeParameters.Request(names=['publish_rate', 'real_time_factor']),
    )
    rate = desc.descriptors[0]
    assert rate.description and rate.floating_point_range[0].to_value == 2000.0
    bad = call(
        collector,
        SetParameters,
        '/football_simulator/set_parameters',
        SetParameters.Request(
            parameters=[Parameter('publish_rate', value=5000.0).to_parameter_msg()]
        ),
    )
    assert not bad.results[0].successful
    good = call(
        collector,
        SetParameters,
        '/football_simulator/set_parameters',
        SetParameters.Request(
            parameters=[Parameter('publish_rate', value=250.0).to_parameter_msg()]
        ),
    )
    assert good.results[0].successful


def test_out_of_range_override_is_one_clear_line(tmp_path):
    proc = subprocess.run(
        [
            sys.executable,
            '-m',
            'football_ros.cli',
            'simulator',
            '--ros-args',
            '-p',
            'publish_rate:=5000.0',
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert 'publish_rate' in proc.stderr and 'Traceback' not in proc.stderr


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_clean_shutdown_mid_flight(start_node, collector, sig):
    node = start_node('simulator', '--ros-args', '-p', 'publish_rate:=1000.0')
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    order_flight(collector, Release(), 'stop-1')
    collector.wait_for(lambda: len(collector.get(qos.POSE)) > 100, 10.0, 'poses')
    assert node.stop(sig) == 0
    assert 'Traceback' not in node.log()


def test_params_yaml_lists_every_parameter_and_loads(start_node, collector):
    from conftest import REPO
    from rcl_interfaces.srv import ListParameters
    import yaml

    config = yaml.safe_load((REPO / 'config' / 'football.yaml').read_text())
    start_node('simulator', '--ros-args', '--params-file', str(REPO / 'config' / 'football.yaml'))
    start_node('release', '--ros-args', '--params-file', str(REPO / 'config' / 'football.yaml'))
    for node in ('football_simulator', 'football_release'):
        listed = call(
            collector, ListParameters, f'/{node}/list_parameters', ListParameters.Request()
        )
        declared = set(listed.result.names) - {'use_sim_time', 'start_type_description_service'}
        assert declared == set(config[f'/**/{node}']['ros__parameters']), node


def test_model_parameter_forces_the_full_model(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'model:=full', '-p', 'publish_rate:=200.0')
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    order_flight(collector, Release(), 'full-1')  # ordered as paper, flown as full
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the landing')
    expected = Flight.from_release(Release(model='full')).simulate(rate=200.0)
    last = collector.get(qos.POSE)[-1].pose.position
    assert (last.x, last.y) == pytest.approx(
        (expected.positions[-1, 0], expected.positions[-1, 1]), abs=1e-6
    )
    assert last.y < -0.3  # drag and lift: shorter, and right of the vacuum plane


def test_bad_model_parameter_is_refused(tmp_path):
    proc = run_cli('simulator', '--ros-args', '-p', 'model:=magic', timeout=60)
    assert proc.returncode == 2 and 'model' in proc.stderr and 'Traceback' not in proc.stderr


# --- trust: guard, bounded work, namespaces, rivals, clock ------------------------------------
def _finite_msg(msg) -> bool:
    from football_ros.nodes.messages import to_plain

    def walk(v):
        if isinstance(v, float):
            return math.isfinite(v)
        if isinstance(v, dict):
            return all(walk(x) for x in v.values())
        if isinstance(v, list):
            return all(walk(x) for x in v)
        return True

    return walk(to_plain(msg))


def _statuses(collector, name_part=''):
    return [s for arr in collector.get(qos.DIAGNOSTICS) for s in arr.status if name_part in s.name]


def test_absurd_orders_never_publish_non_finite_and_a_refused_order_changes_nothing(
    start_node, collector
):
    from football_ros.nodes.messages import level_of
    from football_ros.requests import FlightOrder
    from std_msgs.msg import String

    node = start_node(
        'simulator', '--ros-args', '-p', 'publish_rate:=200.0', '-p', 'marker_rate:=50.0'
    )
    subscribe_all(collector)
    pub = collector.publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
    collector.wait_for_subscribers(pub)
    good = FlightOrder.from_release('absurd', Release()).to_json()
    import json

    base = json.loads(good)
    absurd = []
    for key, value in (
        ('mass', 1e-300),
        ('inertia_spin', 1e300),
        ('c_m_alpha', 1e308),
        ('diameter', 5e-324),
        ('air_density', 10**400),
        ('inertia_transverse', 1e-12),
    ):
        absurd.append(dict(base, ball_params={key: value}))
    absurd.append(dict(base, angular_velocity=[0.0, 0.0, 1e300]))
    absurd.append(dict(base, velocity=[1e308, 1e308, 0.0]))
    absurd.append(
        dict(
            base,
            ball_params={'inertia_spin': 0.003, 'inertia_transverse': 0.0015},
            angular_velocity=[300.0, 0.0, 0.0],
        )
    )  # too fast for the step: refused
    texts = [json.dumps(a) for a in absurd] + ['{"id": ' * 5000 + '1' + '}' * 5000, '[' * 100000]
    # Orders at the edges of every accepted range (ball parameters and release), whether the
    # simulator accepts them or not, each replacing the previous flight after a few ticks.
    from football_ros.physics.presets import BALL_LIMITS
    from football_ros.physics.release import LIMITS

    rng = np.random.default_rng(7)

    def edge(lo, hi):
        return float(rng.choice([lo, hi, lo + 1e-3 * (hi - lo), hi - 1e-3 * (hi - lo)]))

    for k in range(40):
        kwargs = {key: edge(-2500.0, 2500.0) for key in ('alpha_rate_deg_s', 'beta_rate_deg_s')}
        kwargs.update(spin_rpm=edge(*LIMITS['spin_rpm']))
        kwargs.update(
            speed=edge(1.0, 59.9),
            elevation_deg=edge(1.0, 80.0),
            alpha0_deg=edge(-40, 40),
            beta0_deg=edge(-40, 40),
            spin_rpm=0.999 * kwargs['spin_rpm'],
            position=(0.0, 0.0, edge(*LIMITS['position_z'])),
        )
        key = ('c_m_alpha', 'air_density')[k % 2]
        # (Corners such as alpha0 = beta0 = 60 deg, both rates at 3600 deg/s or 60 m/s do not
        # round-trip inside the full-state ranges of an order: issue 9.4, the order path.)
        try:
            release = Release(
                ball_params={key: edge(*BALL_LIMITS[key])},
                model=('paper', 'full')[(k // 2) % 2],
                **kwargs,
            )
            texts.append(FlightOrder.from_release(f'edge-{k}', release).to_json())
        except ValueError:
            continue
    for text in texts:
        pub.publish(String(data=text))
        time.sleep(0.02)
    # A ball released with the wind has no air speed (its angles are undefined): refused at the
    # order, with the reason on the acknowledgement, and the simulator flies on.
    collector.subscribe(DiagnosticStatus, qos.FLIGHT_ACK, qos.ORDER)
    windy = Release(
        model='full',
        speed=10.0,
        elevation_deg=0.0,
        position=(0.0, 0.0, 2.0),
        aero={'wind': [10.0, 0.0, 0.0]},
    )
    windy_order = json.loads(FlightOrder.from_release('zero-air-speed', windy).to_json())
    windy_order['aero']['wind'] = [float(v) for v in windy.initial_state().velocity]
    pub.publish(String(data=json.dumps(windy_order)))
    collector.wait_for(
        lambda: any(a.name == 'zero-air-speed' for a in collector.get(qos.FLIGHT_ACK)),
        10.0,
        'the refusal',
    )
    [refusal] = [a for a in collector.get(qos.FLIGHT_ACK) if a.name == 'zero-air-speed']
    assert level_of(refusal) == 'ERROR' and 'moves with the wind' in refusal.message
    order_flight(collector, Release(ball='rugby'), 'after-the-error')
    collector.wait_for(lambda: landed_event(collector), 10.0, 'a landing after the error')
    for topic in list(STATE_TYPES) + [qos.MARKERS, qos.DIAGNOSTICS]:
        assert all(_finite_msg(m) for m in collector.get(topic)), topic
    assert collector.get(qos.POSE) and node.proc.poll() is None
    flown = {
        kv.value
        for s in _statuses(collector, 'event')
        for kv in s.values
        if kv.key == 'flight_id' and kv.value.startswith('edge-')
    }
    print(f'{len(flown)} edge orders flown of {len(texts) - 11} built')
    assert len(flown) >= 5


def test_services_answer_at_the_worst_accepted_combination(start_node, collector):
    # Highest rate, markers and trail, with real_time_factor / integration_step at its bound.
    node = start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_rate:=2000.0',
        '-p',
        'marker_rate:=200.0',
        '-p',
        'trail_length:=100000',
        '-p',
        'real_time_factor:=5.0',
        '-p',
        'integration_step:=0.000025',
        '-p',
        'allow_reconfigure:=true',
    )
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE, raw=True)
    collector.subscribe(MarkerArray, qos.MARKERS, qos.MARKERS_QOS)
    order_flight(
        collector, Release(speed=60.0, elevation_deg=80.0, position=(0.0, 0.0, 1000.0)), 'heavy'
    )
    latencies = []
    for k in range(6):
        t0 = time.monotonic()
        assert call(
            collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=k % 2 == 0)
        ).success
        latencies.append(time.monotonic() - t0)
        time.sleep(0.2)
    print('pause/resume latencies [s]:', [round(x, 4) for x in latencies])
    assert max(latencies) < 1.0, latencies
    # One step more per wall second than the bound is refused, naming the reason.
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter

    bad = call(
        collector,
        SetParameters,
        '/football_simulator/set_parameters',
        SetParameters.Request(
            parameters=[Parameter('real_time_factor', value=5.01).to_parameter_msg()]
        ),
    )
    assert not bad.results[0].successful and 'RK4 steps per second' in bad.results[0].reason
    from rclpy.serialization import deserialize_message

    poses = [deserialize_message(m, PoseStamped) for m in collector.get(qos.POSE)]
    stamps = np.array([stamp_ns(p) for p in poses])
    assert len(stamps) > 100
    assert np.all((stamps - stamps[0]) % 500_000 == 0)  # every tick keeps its 0.5 ms grid stamp
    markers = collector.get(qos.MARKERS)
    assert markers and max(len(m.markers[3].points) for m in markers) <= 1000
    assert node.proc.poll() is None


def test_events_while_paused_are_published_and_bounded(start_node, collector):
    from football_ros.requests import FlightOrder
    from std_msgs.msg import String

    start_node('simulator', '--ros-args', '-p', 'diagnostics_rate:=0.1')
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    order_flight(collector, Release(), 'paused-0')
    assert call(collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=True)).success
    pub = collector.publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
    for k in range(300):
        pub.publish(String(data=FlightOrder.from_release(f'paused-{k + 1}', Release()).to_json()))
    collector.wait_for(
        lambda: any(kv.value == 'paused-300' for s in _statuses(collector) for kv in s.values),
        10.0,
        'the last release event while paused',
    )
    assert max(len(arr.status) for arr in collector.get(qos.DIAGNOSTICS)) <= 32 + 2


def test_namespaced_simulator_topics_and_unique_diagnostics(start_node, collector):
    from football_ros.requests import FlightOrder
    from std_msgs.msg import String

    start_node('simulator', '--ros-args', '-r', '__ns:=/team1', '-p', 'diagnostics_rate:=5.0')
    collector.subscribe(PoseStamped, '/team1/football/pose', qos.STATE)
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    collector.wait_for(lambda: _statuses(collector), 10.0, 'diagnostics')
    status = _statuses(collector)[-1]
    assert status.name == 'football_ros: /team1/football_simulator'
    assert status.hardware_id == 'football_ros/team1/football_simulator'
    pub = collector.publisher(String, '/team1/football/flight/order', qos.ORDER)
    collector.wait_for_subscribers(pub)
    text = FlightOrder.from_release('ns-1', Release()).to_json()
    resend_until(
        collector,
        lambda _k: pub.publish(String(data=text)),
        lambda: len(collector.get('/team1/football/pose')) > 5,
        'poses',
    )
    assert collector.get('/team1/football/pose')[0].header.frame_id == 'field'


def test_two_simulators_on_one_domain_warn(start_node, collector):
    from football_ros.nodes.messages import level_of

    first = start_node('simulator', '--ros-args', '-p', 'diagnostics_rate:=5.0')
    start_node(
        'simulator', '--ros-args', '-p', 'diagnostics_rate:=5.0', '-r', '__node:=second_sim'
    )
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)

    def warned():
        return any(
            level_of(s) == 'WARN'
            and '/second_sim (/football/pose)' in s.message
            and s.name == 'football_ros: /football_simulator'
            for s in _statuses(collector)
        )

    collector.wait_for(warned, 10.0, 'a WARN naming the other simulator')
    assert '/second_sim (/football/pose)' in first.log()


def test_publish_clock_stamps_equal_clock_and_odom_rests_after_landing(start_node, collector):
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_rate:=100.0',
        '-p',
        'publish_clock:=true',
        '-p',
        'real_time_factor:=2.0',
        '-p',
        'hold_rate:=10.0',
    )
    collector.subscribe(Odometry, qos.ODOM, qos.STATE)
    collector.subscribe(Clock, qos.CLOCK, qos.CLOCK_QOS)
    order_flight(collector, Release(), 'clock-1')
    collector.wait_for(lambda: landed_event(collector), 10.0, 'the landing')
    n_flight = len(collector.get(qos.ODOM))
    time.sleep(0.6)
    odoms = collector.get(qos.ODOM)
    clocks = {c.clock.sec * 1_000_000_000 + c.clock.nanosec for c in collector.get(qos.CLOCK)}
    stamps = [stamp_ns(o) for o in odoms]
    # Every /clock of the flight's ticks is an odometry's stamp (odometry is reliable and sent
    # at every tick in the air; /clock is best effort, so only what arrived is compared).
    flying = stamps[:n_flight]
    during = {c for c in clocks if flying[0] <= c <= flying[-1]}
    assert during and during <= set(flying), sorted(during - set(flying))[:5]
    assert all(s % 20_000_000 == 0 for s in stamps)  # 2 x 10 ms of simulated time per tick
    landing = odoms[n_flight - 1]
    held = odoms[n_flight:]
    assert len(held) >= 3
    assert landing.twist.twist.linear.x > 20.0  # the landing tick: the impact velocity
    for msg in held:
        t = msg.twist.twist
        assert (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z) == (
            0.0,
        ) * 6
        assert msg.pose.pose.position.z == 0.0
        assert msg.pose.pose.position.x == landing.pose.pose.position.x
    assert odoms[n_flight // 2].twist.twist.angular.x == pytest.approx(600 * 2 * math.pi / 60)


def test_trail_decimation_keeps_the_newest_and_stable_points():
    from football_ros.nodes.messages import decimated

    points = list(range(10_000))
    kept = decimated(points, 0, 1000)
    assert len(kept) <= 1000 and kept[-1] == 9_999 and kept[0] == 0
    later = decimated(points[3:] + [10_000, 10_001, 10_002], 3, 1000)
    assert set(kept[:-1]) - {0, 1, 2} <= set(later)  # the same points stay in the strip
    assert decimated(points[:50], 0, 1000) == points[:50]


def test_use_sim_time_takes_stamps_from_an_external_clock(start_node, collector):
    import threading

    start_node('simulator', '--ros-args', '-p', 'use_sim_time:=true', '-p', 'publish_rate:=100.0')
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    clock_pub = collector.publisher(Clock, qos.CLOCK, qos.CLOCK_QOS)
    stop = threading.Event()
    external_ns = [5_000_000_000_000]  # 5000 s, advancing 1 ms per 10 ms of wall time

    def run_clock():
        while not stop.is_set():
            external_ns[0] += 1_000_000
            sec, nsec = divmod(external_ns[0], 1_000_000_000)
            clock_pub.publish(Clock(clock=mb_time(sec, nsec)))
            time.sleep(0.01)

    thread = threading.Thread(target=run_clock, daemon=True)
    thread.start()
    try:
        order_flight(collector, Release(), 'sim-time-1')
        collector.wait_for(lambda: len(collector.get(qos.POSE)) > 30, 10.0, 'poses')
    finally:
        stop.set()
        thread.join()
    stamps = np.array([stamp_ns(p) for p in collector.get(qos.POSE)[5:]])
    # Stamps are the external clock (about 5000 s), not the wall clock, and never go back.
    assert np.all((stamps >= 5_000_000_000_000) & (stamps <= external_ns[0]))
    assert np.all(np.diff(stamps) >= 0)


def mb_time(sec, nanosec):
    from builtin_interfaces.msg import Time

    return Time(sec=sec, nanosec=nanosec)


def test_parameter_combinations():
    from football_ros.nodes import simulator as sim

    values = {spec.name: spec.default for spec in sim.PARAMETERS}
    assert sim.check_parameters(values) is None
    assert 'RK4 steps per second' in sim.check_parameters(
        dict(values, real_time_factor=100.0, integration_step=1e-5)
    )
    assert (
        sim.check_parameters(dict(values, real_time_factor=100.0, integration_step=5e-4)) is None
    )
    # A flight in the air with a smaller step than the next one counts too.
    assert sim.check_parameters(dict(values, real_time_factor=10.0), flight_step=1e-5)
    frames = {s.name: s for s in sim.PARAMETERS if s.name in ('frame_id', 'child_frame_id')}
    for name, spec in frames.items():  # a rule of the row itself, checked on every set
        assert spec.check('') == f"'{name}' must not be empty"


def _fifo_threads(pid: int) -> list[int]:
    """Real-time priorities of the threads of ``pid`` on SCHED_FIFO."""
    from pathlib import Path

    found = []
    for task in Path(f'/proc/{pid}/task').iterdir():
        try:
            policy = os.sched_getscheduler(int(task.name)) & ~os.SCHED_RESET_ON_FORK
            if policy == os.SCHED_FIFO:
                found.append(os.sched_getparam(int(task.name)).sched_priority)
        except OSError:  # a thread that just ended
            pass
    return found


def test_thread_priority_puts_the_pacer_and_executor_on_sched_fifo_or_says_why_not(
        start_node, collector):
    normal = start_node('simulator')
    assert 'pacing on the normal scheduler' in normal.log()
    assert _fifo_threads(normal.pid) == []
    normal.stop()
    node = start_node('simulator', '--ros-args', '-p', 'thread_priority:=7')
    log = node.log()
    if 'SCHED_FIFO refused' in log:  # no rtprio limit here: a warning, the normal scheduler
        assert 'thread_priority 7' in log and 'pacing on the normal scheduler' in log
        assert _fifo_threads(node.pid) == []
        expected = 'normal scheduler'
    else:  # the pacing thread at priority 7, the executor (main) thread below it, no other
        assert 'pacing on the SCHED_FIFO priority 7 (executor 6)' in log
        assert sorted(_fifo_threads(node.pid)) == [6, 7]
        assert os.sched_getparam(node.pid).sched_priority == 6  # the main thread's id: the pid
        expected = 'SCHED_FIFO priority 7 (executor 6)'
    collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    collector.wait_for(lambda: any(
        kv.key == 'pacing' and kv.value == expected
        for msg in collector.get(qos.DIAGNOSTICS) for st in msg.status for kv in st.values),
        10.0, 'the pacing on /diagnostics')
    out = subprocess.run(
        [sys.executable, '-m', 'football_ros.cli', 'simulator', '--ros-args', '-p',
         'thread_priority:=100'], capture_output=True, text=True, timeout=60)
    assert out.returncode != 0 and 'thread_priority' in out.stderr
