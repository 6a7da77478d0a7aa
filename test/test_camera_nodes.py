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
Camera rigs across processes.

The simulator's CameraInfo, detections and /tf_static, the tracker fusing them, and hostile
camera input.
"""

import math
from pathlib import Path
import time

from football_ros.estimation.detections import sampled_flight
from football_ros.estimation.rig import load_rig
from football_ros.nodes import messages as mb
from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from football_ros.physics.frames import quaternion_to_matrix
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TransformStamped
import numpy as np
import pytest
from rosutil import order_flight
from sensor_msgs.msg import CameraInfo

pytestmark = pytest.mark.skipif(mb.Detection2DArray is None, reason='no vision_msgs')
RIG = Path(__file__).resolve().parents[1] / 'config' / 'rig_stereo.yaml'


def stamp_s(msg):
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_simulator_publishes_the_rig_and_the_tracker_fuses_its_pixels(start_node, collector):
    rig = load_rig(RIG)
    names = [c.name for c in rig]
    start_node(
        'simulator', '--ros-args', '-p', 'model:=full', '-p', 'publish_rate:=200.0',
        '-p', f'camera_rig:={RIG}', '-p', 'hold_rate:=0.0', '-p', 'publish_clock:=true',
    )
    tracker = start_node(
        'tracker', '--ros-args', '-p', f'cameras:=[{", ".join(names)}]',
        '-p', 'prediction_rate:=10.0',
    )
    for name in names:
        collector.subscribe(CameraInfo, qos.camera_topic(name, 'camera_info'), qos.STATE)
        collector.subscribe(mb.Detection2DArray, qos.camera_topic(name, 'detections'), qos.STATE)
    collector.subscribe(mb.TFMessage, qos.TF_STATIC, qos.TF_STATIC_QOS)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    collector.subscribe(PoseWithCovarianceStamped, qos.LANDING, qos.STATE)
    detections = '/' + qos.camera_topic(names[0], 'detections')
    collector.wait_for(
        lambda: collector.node.count_subscribers(detections) >= 2 and collector.get(qos.TF_STATIC),
        20.0, 'the tracker, the cameras and /tf_static',
    )
    # /tf_static: each optical frame where the rig puts it
    (static,) = collector.get(qos.TF_STATIC)
    poses = {t.child_frame_id: t for t in static.transforms}
    for cam in rig:
        t = poses[cam.frame_id]
        assert t.header.frame_id == 'field'
        p, q = t.transform.translation, t.transform.rotation
        assert np.allclose([p.x, p.y, p.z], cam.camera.position)
        assert np.allclose(quaternion_to_matrix(np.array([q.x, q.y, q.z, q.w])),
                           cam.camera.rotation, atol=1e-12)
    time.sleep(1.0)
    release = Release(speed=20.0, elevation_deg=30.0, spin_rpm=600.0, position=(0.0, 0.0, 1.8))
    order_flight(collector, release, 'cams-1')
    collector.wait_for(lambda: len(collector.get(qos.LANDING)) > 0, 20.0, 'a prediction')
    truth = Flight.from_release(release.replace(model='full')).simulate(rate=1000.0)
    balls_at = sampled_flight(truth.times, truth.positions, truth.velocities, truth.axes)
    tracker.wait_for_log('ended: landed', timeout=180.0)  # it may lag on a loaded machine
    time.sleep(1.0)
    release_stamp = stamp_s(collector.get(qos.POSE)[0])
    for cam in rig:
        frames = collector.get(qos.camera_topic(cam.name, 'detections'))
        infos = collector.get(qos.camera_topic(cam.name, 'camera_info'))
        assert len(infos) == len(frames)
        assert infos[0].header.frame_id == frames[0].header.frame_id == cam.frame_id
        assert np.allclose(infos[0].k, cam.camera.K.ravel())
        assert list(infos[0].d) == list(cam.camera.D)
        stamps = np.array([stamp_s(f) for f in frames]) - release_stamp
        # exposures at k / 120 s of flight time (0.1 ms jitter), none after the landing
        assert np.abs(stamps - np.round(stamps * 120) / 120).max() < 0.0006
        assert stamps[-1] <= truth.times[-1] + 1e-6 and len(stamps) > 0.9 * 120 * truth.times[-1]
        errors = []
        for f, t in zip(frames, stamps):
            centres, axes = balls_at(float(t))
            for d in f.detections:
                truth_px = cam.camera.project(centres[0])[0]
                c = d.bbox.center.position
                errors.append(math.hypot(c.x - truth_px[0], c.y - truth_px[1]))
                assert d.bbox.size_x >= d.bbox.size_y > 2.0
        errors = np.array(errors)
        assert len(errors) > 0.8 * len(frames)
        assert np.median(errors) < 2.0 and np.mean(errors < 5.0) > 0.95  # 1 px, 1 % outliers
    final = collector.get(qos.LANDING)[-1].pose.pose.position
    x_land, y_land = truth.positions[-1, :2]
    assert math.hypot(final.x - x_land, final.y - y_land) < 0.3, tracker.log()[-2000:]
    log = tracker.log()
    assert 'new throw' in log and 'Traceback' not in log


def _info(frame='cam_optical', k=(1000.0, 0, 640.0, 0, 1000.0, 360.0, 0, 0, 1.0)):
    msg = CameraInfo(width=1280, height=720, distortion_model='plumb_bob', k=list(k))
    msg.d = [0.0] * 5
    msg.r = [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]
    msg.header.frame_id = frame
    return msg


def _detections(stamp, centers, frame='cam_optical', size=(12.0, 8.0)):
    msg = mb.Detection2DArray()
    msg.header.frame_id = frame
    sec = int(math.floor(stamp))
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, int((stamp - sec) * 1e9)
    for c in centers:
        d = mb.Detection2D()
        d.bbox.center.position.x, d.bbox.center.position.y = float(c[0]), float(c[1])
        d.bbox.size_x, d.bbox.size_y = size
        msg.detections.append(d)
    return msg


def test_hostile_camera_input_is_refused_with_a_reason(start_node, collector):
    tracker = start_node('tracker', '--ros-args', '-p', 'cameras:=[cam]')
    info = collector.publisher(CameraInfo, qos.camera_topic('cam', 'camera_info'), qos.STATE)
    dets = collector.publisher(
        mb.Detection2DArray, qos.camera_topic('cam', 'detections'), qos.STATE
    )
    static = collector.publisher(mb.TFMessage, qos.TF_STATIC, qos.TF_STATIC_QOS)
    collector.wait_for_subscribers(dets)
    collector.wait_for_subscribers(info)
    now = time.time()
    dets.publish(_detections(now, [(600, 300)]))  # no camera_info yet
    tracker.wait_for_log('no camera_info yet')
    info.publish(_info(k=(0.0,) * 9))  # an uncalibrated camera
    tracker.wait_for_log("camera_info refused: camera 'K'")
    info.publish(_info())
    time.sleep(0.5)
    dets.publish(_detections(now, [(600, 300)]))  # its frame unknown
    tracker.wait_for_log("no static transform from 'field' to its frame 'cam_optical'")
    t = TransformStamped(child_frame_id='cam_optical')
    t.header.frame_id = 'field'
    t.transform.rotation.w = 1.0
    t.transform.translation.z = math.nan
    static.publish(mb.TFMessage(transforms=[t]))
    tracker.wait_for_log('non-finite translation')
    t.transform.translation.z = 2.0
    static.publish(mb.TFMessage(transforms=[t]))
    time.sleep(0.5)
    for bad, why in (
        (_detections(now, [(math.nan, 300)]), 'non-finite centre'),
        (_detections(now, [(600, 300)], size=(0.3, 0.2)), 'width 0.2 px outside'),
        (_detections(now, [(5000, 300)]), 'outside the 1280x720 image'),
        (_detections(now, [(600, 300)], frame='other'), "detections in frame 'other'"),
    ):
        dets.publish(bad)
        tracker.wait_for_log(why)
    # a camera that lies about its rate: stamps 4 x too far apart, 200 frames, then garbage
    for k in range(200):
        dets.publish(_detections(now - 10.0 + 4 * k / 60.0, [(600 + k, 300 - k)]))
    time.sleep(1.0)
    assert tracker.proc.poll() is None, tracker.log()
    log = tracker.log()
    assert 'Traceback' not in log and 'internal error' not in log, log
