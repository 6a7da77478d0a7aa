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

import dataclasses

import numpy as np
from sensor_msgs.msg import CameraInfo

from . import messages as mb
from . import qos
from ..estimation.detections import RigSimulator, sampled_flight
from ..estimation.rig import RigCamera
from ..physics.frames import body_x_axis


class CameraRigPublisher:
    """Publishers, simulators and the static transforms of one rig on ``node``."""

    def __init__(self, node, rig: tuple[RigCamera, ...], frame_id: str) -> None:
        if mb.Detection2DArray is None:
            raise ValueError('vision_msgs is not installed: no camera detections')
        self._node, self.rig = node, rig
        self._ball = None  # the flight's ball preset (its size and name)
        self._info = {
            c.name: node.create_publisher(
                CameraInfo, qos.camera_topic(c.name, qos.CAMERA_INFO), qos.STATE
            )
            for c in rig
        }
        self._detections = {
            c.name: node.create_publisher(
                mb.Detection2DArray, qos.camera_topic(c.name, qos.DETECTIONS), qos.STATE
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
        self._run = None
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
        if run is None:
            self._run = None
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
        if flight.landing_time is not None:
            frames += self._sim.flush()
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
