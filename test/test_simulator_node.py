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
import signal
import subprocess
import sys
import time

from diagnostic_msgs.msg import DiagnosticArray
from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from football_ros.physics.frames import quaternion_to_matrix
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rosgraph_msgs.msg import Clock
from rosutil import call, landed_event, order_flight
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

STATE_TYPES = {
    qos.POSE: PoseStamped,
    qos.ODOM: Odometry,
    qos.SPIN_AXIS: Vector3Stamped,
    qos.AERO_ANGLES: Vector3Stamped,
    qos.AERO_ANGLES_LINEAR: Vector3Stamped,
}


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
    time.sleep(0.3)

    msgs = {topic: collector.get(topic) for topic in STATE_TYPES}
    counts = {topic: len(m) for topic, m in msgs.items()}
    expected = Flight.from_release(release).simulate(rate=rate, duration=10.0)
    assert set(counts.values()) == {len(expected.times)}, counts  # every tick, landing included
    # Same stamp on every topic for each tick; stamps exactly 1/rate apart.
    stamps = np.array([[stamp_ns(m) for m in msgs[t]] for t in STATE_TYPES])
    assert np.all(stamps == stamps[0])
    steps = np.diff(stamps[0])
    assert np.all(np.abs(steps - 1e9 / rate) <= 1), steps
    # Frames.
    for topic in STATE_TYPES:
        assert all(m.header.frame_id == 'field' for m in msgs[topic])
    assert all(m.child_frame_id == 'football' for m in msgs[qos.ODOM])
    # alpha/beta/delta and the linear prediction equal the headless run, sample by sample.
    aero = np.array([[m.vector.x, m.vector.y, m.vector.z] for m in msgs[qos.AERO_ANGLES]])
    assert np.max(np.abs(aero[:-1] - expected.aero_angles[:-1])) < 1e-9
    assert np.max(np.abs(aero[-1] - expected.aero_angles[-1])) < 1e-6  # landing row
    linear = np.array([[m.vector.x, m.vector.y] for m in msgs[qos.AERO_ANGLES_LINEAR]])
    assert np.max(np.abs(linear - expected.aero_angles_linear)) < 1e-6
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
    n_landed = len(collector.get(qos.AERO_ANGLES))
    arrivals = np.array(collector.arrivals[qos.AERO_ANGLES][:n_landed])
    # Wall-clock duration of the flight matches the simulated 2.04 s (real-time factor 1).
    assert (arrivals[-1] - arrivals[0]) * 1e-9 == pytest.approx(2.039, abs=0.15)
    time.sleep(1.1)
    held = collector.get(qos.AERO_ANGLES)[n_landed:]
    assert 3 <= len(held) <= 7  # 5 Hz hold of the landed state
    assert all(m.vector.x == collector.get(qos.AERO_ANGLES)[n_landed - 1].vector.x for m in held)


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

    start_node('simulator')
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
    proc = subprocess.run(
        [
            sys.executable,
            '-m',
            'football_ros.cli',
            'simulator',
            '--ros-args',
            '-p',
            'model:=magic',
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2 and 'model' in proc.stderr and 'Traceback' not in proc.stderr
