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
A camera rig's topics: each camera's CameraInfo and ball detections, its optical frame.

:class:`CameraRigPublisher` (the simulator's) publishes them; :class:`CameraInputs` (the
tracker's) reads them, from this package's simulator or any other camera driver and detector.

A thin adapter around :class:`football_ros.estimation.detections.RigSimulator` (the models
live there; the rig file: :mod:`football_ros.estimation.rig`). Per camera ``<name>``:
``football/camera/<name>/camera_info`` (sensor_msgs/msg/CameraInfo) and
``football/camera/<name>/detections`` (vision_msgs/msg/Detection2DArray), one each per frame,
stamped with the frame's exposure time (header.frame_id = the camera's optical frame); every
optical frame in the world frame on /tf_static once, at start-up (transient local).

The owner calls :meth:`CameraRigPublisher.tick` once per tick with its flight run, the tick's
stamp and the flight time [s], before it samples the flight. Exposures are at phase + k / rate
of flight time after the flight's first tick (each flight restarts the cameras, their seeds
advanced by one); the ball at an exposure is the cubic Hermite interpolation of the states at
the ticks around it (a 10 ms tick: micrometres). Frames are published at the first tick at or
after their delivery time, and those still waiting when the ball lands at the landing tick
(their stamps their exposure times).
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import math
import re
import time

import numpy as np
from sensor_msgs.msg import CameraInfo

from . import messages as mb
from . import qos
from ..estimation.camera import Camera
from ..estimation.detections import RigSimulator, sampled_flight
from ..estimation.rig import RigCamera
from ..physics.frames import body_x_axis, quaternion_to_matrix


class CameraRigPublisher:
    """Publishers, simulators and the static transforms of one rig on ``node``."""

    def __init__(self, node, rig: tuple[RigCamera, ...], frame_id: str) -> None:
        if mb.Detection2DArray is None:
            raise ValueError('vision_msgs is not installed: no camera detections')
        self._node, self.rig = node, rig
        self._ball = None  # the flight's ball preset (its size and name)
        self._info = {
            c.name: node.create_publisher(
                CameraInfo, qos.camera_topic(c.name, 'camera_info'), qos.STATE
            )
            for c in rig
        }
        self._detections = {
            c.name: node.create_publisher(
                mb.Detection2DArray, qos.camera_topic(c.name, 'detections'), qos.STATE
            )
            for c in rig
        }
        self._frames = {c.name: c.frame_id for c in rig}
        self._cameras = {c.name: c.camera for c in rig}
        self._static = node.create_publisher(mb.TFMessage, qos.TF_STATIC, qos.TF_STATIC_QOS)
        self._static.publish(mb.static_transforms(
            [(c.frame_id, c.camera.rotation, c.camera.position) for c in rig],
            node.get_clock().now().to_msg(), frame_id,
        ))
        self._run = self._done = None  # the flight run ticked last; the one that landed
        self._sim: RigSimulator | None = None
        self._flights = 0
        self.published = 0
        """Frames published over the node's life."""

    def tick(self, run, stamp, now: float) -> None:
        """
        Expose and publish what is due at this tick.

        ``run`` the flight run (None: no flight), ``stamp`` the tick's
        builtin_interfaces/Time, ``now`` its flight time [s]. With the
        node's ``publish_clock`` false, stamps are wall time (1 / real_time_factor per flight
        second), as the simulator's.
        """
        node = self._node
        scale = 1.0 if node.publish_clock else 1.0 / node.real_time_factor
        if run is None or run is self._done:
            self._run = None if run is None else run
            return
        flight = run.flight
        state = flight.state_at(now)  # the landing state once landed
        end = now if flight.landing_time is None else min(now, flight.landing_time)
        sample = (end, state[:3].copy(), state[3:6].copy(), body_x_axis(state[6:10]))
        if run is not self._run:
            self._run, self._ball, self._prev = run, flight.ball, None
            self._flights += 1
            self._sim = RigSimulator(
                tuple(dataclasses.replace(c, seed=c.seed + self._flights) for c in self.rig),
                self._ball.length, self._ball.diameter,
            )
            self._sim.start(now)
        prev, self._prev = self._prev, sample
        frames = self._sim.step(now, _between(prev, sample))
        if flight.landing_time is not None:  # the last frames; no more exposures of this run
            frames += self._sim.flush()
            self._done = run
        stamp_ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        for frame in frames:
            at = mb.time_msg(stamp_ns - int(round((now - frame.stamp) * scale * 1e9)))
            frame_id = self._frames[frame.camera]
            self._info[frame.camera].publish(
                mb.camera_info(self._cameras[frame.camera], at, frame_id)
            )
            self._detections[frame.camera].publish(
                mb.detection_array(frame.detections, at, frame_id, self._ball.name)
            )
            self.published += 1


def _between(prev, sample):
    """balls_at(t) between two (t, position, velocity, axis) samples (no ball outside them)."""
    empty = (np.zeros((0, 3)), np.zeros((0, 3)))

    def balls_at(t: float):
        if prev is None or not prev[0] <= t <= sample[0] or sample[0] <= prev[0]:
            return empty
        return sampled_flight(*zip(prev, sample))(t)

    return balls_at


LOG_PERIOD = 2.0
"""Seconds between two log lines of the same kind of refusal of the same camera."""
MAX_FRAMES = 1000
"""Most static transforms kept from /tf_static (a flood of new frames is refused beyond)."""
MAX_CHAIN = 16
"""Longest chain of static transforms followed from a camera's frame to the world frame."""


class CameraInputs:
    """
    The tracker's camera subscriptions: CameraInfo, Detection2DArray and /tf_static.

    For each camera name: ``football/camera/<name>/camera_info`` (its intrinsics, the newest
    valid one kept), ``football/camera/<name>/detections``, and the pose of the camera's
    frame (header.frame_id of its CameraInfo) in the world frame ``frame_id``, composed from
    the static transforms on /tf_static. Each detection of a frame whose camera is fully known
    goes to ``on_detection(stamp [s], camera name, Camera, centre (2,) [px], width [px])``
    (width: the box's short side); anything else is refused with a throttled warning naming
    the camera and what is wrong, and counted in :attr:`refused`.
    """

    def __init__(self, node, names, frame_id: str, on_detection) -> None:
        if mb.Detection2DArray is None:
            raise ValueError('vision_msgs is not installed: no camera detections')
        self._node, self._frame_id, self._on_detection = node, frame_id, on_detection
        self._info: dict[str, tuple] = {}  # name -> (frame_id, CameraInfo fields)
        self._cameras: dict[str, Camera] = {}  # name -> posed camera
        self._static: dict[str, tuple] = {}  # child -> (parent, rotation, translation)
        self.refused: collections.Counter = collections.Counter()
        self._said: dict[tuple, float] = {}  # kind of refusal -> when last logged
        for name in names:
            node.create_subscription(
                CameraInfo, qos.camera_topic(name, 'camera_info'),
                functools.partial(self._guard, self._on_info, name), qos.STATE,
            )
            node.create_subscription(
                mb.Detection2DArray, qos.camera_topic(name, 'detections'),
                functools.partial(self._guard, self._on_detections, name), qos.STATE,
            )
        node.create_subscription(
            mb.TFMessage, qos.TF_STATIC, functools.partial(self._guard, self._on_static, None),
            qos.TF_STATIC_QOS,
        )

    def _guard(self, handler, name, msg) -> None:
        try:
            handler(name, msg)
        except Exception as exc:  # noqa: BLE001 - a bad message must never stop the node
            self.refuse(name, f'ignored after an internal error: {exc!r}'[:200])

    def refuse(self, name, why: str) -> None:
        """Count a refusal of camera ``name`` (None: /tf_static); log it, each kind 1 / 2 s."""
        self.refused[name] += 1
        kind = (name, re.sub(r'[-+.0-9e]+', '#', why)[:60])
        now = time.monotonic()
        if now - self._said.get(kind, -math.inf) < LOG_PERIOD:
            return
        if len(self._said) >= 1000:
            self._said.clear()
        self._said[kind] = now
        text = f"camera '{name}': {why}" if name else f'/tf_static: {why}'
        self._node.get_logger().warning(text)

    def _on_info(self, name: str, msg) -> None:
        try:
            r, p = np.array(msg.r, dtype=float), np.array(msg.p, dtype=float)
            fields = {  # all-zero R and P: not given (as an unrectified camera sends)
                'width': int(msg.width), 'height': int(msg.height), 'K': np.array(msg.k),
                'D': np.array(msg.d), 'distortion_model': msg.distortion_model,
                'R': np.eye(3) if not np.any(r) else r, 'P': None if not np.any(p) else p,
            }
            Camera(**fields)  # checked now, posed when its frame is known
        except (ValueError, TypeError) as exc:
            self.refuse(name, f'camera_info refused: {exc}')
            return
        frame = msg.header.frame_id
        if self._info.get(name, (None, None))[0] != frame or name not in self._cameras:
            self._info[name] = (frame, fields)
            self._pose(name)
        else:
            self._info[name] = (frame, fields)

    def _on_static(self, _name, msg) -> None:
        changed = False
        for t in msg.transforms:
            child, parent = t.child_frame_id, t.header.frame_id
            q = (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
                 t.transform.rotation.w)
            p = (t.transform.translation.x, t.transform.translation.y,
                 t.transform.translation.z)
            norm = float(np.linalg.norm(q))
            if not (child and parent and np.all(np.isfinite(p)) and abs(norm - 1.0) < 1e-3):
                self.refuse(None, f"transform to '{child[:40]}' refused: empty frame, "
                            'non-finite translation or a rotation that is not a unit quaternion')
                continue
            if child not in self._static and len(self._static) >= MAX_FRAMES:
                self.refuse(None, f'more than {MAX_FRAMES} static frames: the rest ignored')
                break
            self._static[child] = (parent, quaternion_to_matrix(np.array(q) / norm), np.array(p))
            changed = True
        if changed:
            for name in self._info:
                self._pose(name)

    def _pose(self, name: str) -> None:
        """Pose the camera ``name`` if its frame reaches the world frame (else unposed)."""
        frame, fields = self._info[name]
        pose = static_pose(self._static, frame, self._frame_id)
        if pose is None:
            self._cameras.pop(name, None)
            return
        self._cameras[name] = Camera(**fields, rotation=pose[0], position=pose[1])

    def _on_detections(self, name: str, msg) -> None:
        camera = self._cameras.get(name)
        if camera is None:
            known = name in self._info
            self.refuse(name, 'detections ignored: ' + (
                f"no static transform from '{self._frame_id}' to its frame "
                f"'{self._info[name][0][:40]}' yet" if known else 'no camera_info yet'))
            return
        if msg.header.frame_id != self._info[name][0]:
            self.refuse(name, f"detections in frame '{msg.header.frame_id[:40]}', not its "
                        f"camera_info's '{self._info[name][0][:40]}': ignored")
            return
        stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        for det in msg.detections[:MAX_DETECTIONS]:
            box = det.bbox
            center = (box.center.position.x, box.center.position.y)
            width = min(box.size_x, box.size_y)
            self._on_detection(stamp, name, camera, center, width)
        if len(msg.detections) > MAX_DETECTIONS:
            self.refuse(name, f'more than {MAX_DETECTIONS} detections in a frame: the rest '
                        'ignored')


MAX_DETECTIONS = 16
"""Most detections of one frame taken (a detector's flood of boxes is cut)."""


def static_pose(static: dict, frame: str, root: str):
    """
    Return (rotation 3x3, position [m]) of ``frame`` in ``root`` from static transforms.

    ``static``: child -> (parent, rotation, translation); None if no chain of at most
    :data:`MAX_CHAIN` links joins them.
    """
    rotation, position = np.eye(3), np.zeros(3)
    for _ in range(MAX_CHAIN):
        if frame == root:
            return rotation, position
        link = static.get(frame)
        if link is None:
            return None
        parent, rot, trans = link
        rotation, position = rot @ rotation, rot @ position + trans
        frame = parent
    return None
