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
TF: the ball as the frame ``football`` in ``field`` on /tf (tf2_msgs/TFMessage).

And the tf2_msgs built for the pip ROS (pip_ros/tf2_msgs) is wire-compatible with Jazzy's.
"""

import time

from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from geometry_msgs.msg import PoseStamped
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from rosutil import call, landed_event, order_flight
from std_srvs.srv import SetBool
import yaml

tf2_msgs = pytest.importorskip('tf2_msgs.msg', reason='tf2_msgs not built (scripts/setup.sh)')
TFMessage = tf2_msgs.TFMessage

# `ros2 topic info -v /tf` on ROS 2 Jazzy (and rosbags' Jazzy type store, computed below).
JAZZY_TFMESSAGE_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'


def ns(stamp):
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def test_tf2_msgs_has_jazzys_definition_and_type_hash(collector):
    pub = collector.publisher(TFMessage, '/tf_hash_probe', qos.TF_QOS)
    infos = collector.node.get_publishers_info_by_topic('/tf_hash_probe')
    assert str(infos[0].topic_type_hash) == JAZZY_TFMESSAGE_HASH
    assert (
        get_typestore(Stores.ROS2_JAZZY).hash_rihs01('tf2_msgs/msg/TFMessage')
        == JAZZY_TFMESSAGE_HASH
    )
    assert TFMessage.get_fields_and_field_types() == {
        'transforms': 'sequence<geometry_msgs/TransformStamped>'
    }
    collector.node.destroy_publisher(pub)


def test_ball_frame_on_tf_follows_the_pose_through_pause_and_hold(start_node, collector, tmp_path):
    bag = tmp_path / 'tf_bag'
    sim = start_node(
        'simulator', '--ros-args', '-p', 'publish_rate:=200.0', '-p', 'hold_rate:=20.0'
    )
    recorder = start_node(
        'record', '--out', str(bag), '--topics', '/tf', 'football/pose', '/diagnostics'
    )
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    recorder.wait_for_log("recording '/diagnostics'")  # the simulator reaches the recorder
    order_flight(collector, Release(), 'tf-1')
    collector.wait_for(lambda: len(collector.get(qos.TF)) >= 100, 10.0, '100 transforms')
    assert call(collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=True)).success
    time.sleep(0.2)  # what was in flight arrives
    paused_count = len(collector.get(qos.TF))
    time.sleep(0.6)
    assert len(collector.get(qos.TF)) == paused_count  # nothing while paused
    assert call(collector, SetBool, qos.PAUSE_SERVICE, SetBool.Request(data=False)).success
    collector.wait_for(lambda: landed_event(collector), 15.0, 'the landing')
    time.sleep(0.5)  # about ten held states at 20 Hz
    assert sim.stop() == 0
    time.sleep(0.3)
    assert recorder.stop() == 0

    tfs, poses = collector.get(qos.TF), collector.get(qos.POSE)
    transforms = [t for msg in tfs for t in msg.transforms]
    assert len(transforms) == len(tfs) == len(poses)
    assert all(t.header.frame_id == 'field' and t.child_frame_id == 'football' for t in transforms)
    stamps = np.array([ns(t.header.stamp) for t in transforms])
    assert np.all(np.diff(stamps) > 0)  # strictly increasing: tf2 never sees repeated data
    by_stamp = {ns(p.header.stamp): p.pose for p in poses}
    for t in transforms:
        pose = by_stamp[ns(t.header.stamp)]
        tr, rot = t.transform.translation, t.transform.rotation
        assert (tr.x, tr.y, tr.z) == (pose.position.x, pose.position.y, pose.position.z)
        assert (rot.x, rot.y, rot.z, rot.w) == (
            pose.orientation.x,
            pose.orientation.y,
            pose.orientation.z,
            pose.orientation.w,
        )
    # Against the headless flight, tick by tick (the pause only delays the ticks).
    expected = Flight.from_release(Release()).simulate(rate=200.0)
    n = len(expected.times)
    got = np.array(
        [
            [t.transform.translation.x, t.transform.translation.y, t.transform.translation.z]
            for t in transforms
        ]
    )
    assert len(got) > n + 5  # the flight, then held landed states
    assert np.max(np.abs(got[:n] - expected.positions)) < 1e-6
    assert np.max(np.abs(got[n:] - expected.positions[-1])) < 1e-6  # held at the landing point

    # The recorder records /tf like any topic.
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        counts = {}
        for conn, _t, raw in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            if conn.topic == '/tf':
                last = reader.deserialize(raw, conn.msgtype)
    assert (counts['/tf'], counts['/football/pose']) == (len(tfs), len(poses))
    assert last.transforms[0].transform.translation.x == pytest.approx(got[-1][0], abs=1e-12)
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    topics = {
        t['topic_metadata']['name']: t['topic_metadata'] for t in meta['topics_with_message_count']
    }
    assert topics['/tf']['type_description_hash'] == JAZZY_TFMESSAGE_HASH


def test_publish_tf_false_switches_tf_off(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'publish_rate:=200.0', '-p', 'publish_tf:=false')
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    order_flight(collector, Release(), 'tf-off')
    collector.wait_for(lambda: len(collector.get(qos.POSE)) >= 100, 10.0, '100 poses')
    time.sleep(0.3)
    assert collector.get(qos.TF) == []


def test_tf_with_sim_clock_follows_clock(start_node, collector):
    """With publish_clock the transforms carry /clock time, strictly increasing."""
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_rate:=200.0',
        '-p',
        'publish_clock:=true',
        '-p',
        'real_time_factor:=2.0',
    )
    collector.subscribe(TFMessage, qos.TF, qos.TF_QOS)
    order_flight(collector, Release(), 'tf-clock')
    collector.wait_for(lambda: len(collector.get(qos.TF)) >= 200, 10.0, '200 transforms')
    stamps = np.array([ns(m.transforms[0].header.stamp) for m in collector.get(qos.TF)])
    steps = np.diff(stamps)
    assert np.all(steps > 0)
    assert np.median(steps) == 10_000_000  # 2 x 1/200 s of simulated time per tick
    assert stamps[0] < 100e9  # simulated time since the simulator started, not the wall clock
