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
Simulated ball detections of a rig's cameras (:mod:`.rig`), seeded so that runs repeat.

What a detector on each camera would report.

Each camera exposes at phase + k / rate [s] on the caller's clock, on its own (the cameras are
not synchronised). A ball in view (:meth:`.camera.Camera.in_view` of its centre) is detected
unless dropped (``dropout``); the detection is its image (:func:`.camera.ball_image`: centre
pixel, outline's long and short axes and angle) with Gaussian ``pixel_noise`` on the centre
and on both axes, or, with probability ``outlier_rate``, a centre anywhere in the image. The
frame is stamped with its exposure time plus Gaussian ``stamp_jitter`` and delivered
``latency`` later; frames wait in a queue of at most rate x latency + :data:`QUEUE_DEPTH`
(the oldest dropped first, counted). A frame with no detection is still delivered (empty).
"""

from __future__ import annotations

import collections
from dataclasses import dataclass
import math
from typing import Callable

import numpy as np

from .camera import ball_image
from .rig import RigCamera

QUEUE_DEPTH = 256
"""Frames of slack in a camera's queue beyond those in flight (rate x latency)."""


@dataclass(frozen=True)
class Detection:
    """One ball in one frame: ``center`` (2,) [px], ``length``, ``width`` [px], ``angle`` [rad]."""

    center: np.ndarray
    length: float
    width: float
    angle: float
    outlier: bool = False


@dataclass(frozen=True)
class Frame:
    """
    One exposure of one camera.

    Its ``stamp`` (exposure time with jitter) [s], true ``exposure`` time [s], ``delivery``
    time [s] and ``detections``.
    """

    camera: str
    stamp: float
    exposure: float
    delivery: float
    detections: tuple[Detection, ...]


BallsAt = Callable[[float], tuple[np.ndarray, np.ndarray]]
"""balls_at(t) -> (centres (n, 3) [m], unit long axes (n, 3)) in ``field`` at time t [s]."""


class CameraSimulator:
    """One rig camera's detections of the balls of ``balls_at`` (:meth:`step` along a flight)."""

    def __init__(self, rig_camera: RigCamera, length: float, diameter: float) -> None:
        self.spec = rig_camera
        self.length, self.diameter = float(length), float(diameter)
        self._rng = np.random.default_rng(rig_camera.seed)
        self.depth = int(math.ceil(rig_camera.rate * rig_camera.latency)) + QUEUE_DEPTH
        self._queue: collections.deque[Frame] = collections.deque()
        self.counts: collections.Counter = collections.Counter()
        self._next_k = 0

    def start(self, now: float) -> None:
        """Take the next exposure at the first phase + k / rate after ``now`` [s]."""
        s = self.spec
        self._next_k = max(self._next_k, int(math.floor((now - s.phase) * s.rate)) + 1)

    def frame(self, exposure: float, centres: np.ndarray, axes: np.ndarray) -> Frame:
        """Return the frame exposed at ``exposure`` [s] of balls at ``centres`` with ``axes``."""
        s, cam = self.spec, self.spec.camera
        found = []
        centres = np.asarray(centres, dtype=float).reshape(-1, 3)
        axes = np.asarray(axes, dtype=float).reshape(-1, 3)
        visible = cam.in_view(centres) if len(centres) else np.zeros(0, bool)
        for centre, axis, seen in zip(centres, axes, visible):
            draws = self._rng.random(2)
            noise = self._rng.normal(0.0, s.pixel_noise, 4)
            if not seen or draws[0] < s.dropout:
                self.counts['missed' if seen else 'out_of_view'] += 1
                continue
            image = ball_image(cam, centre, axis, self.length, self.diameter)
            if image is None:
                self.counts['out_of_view'] += 1
                continue
            centre_px = image.center + noise[:2]
            outlier = bool(draws[1] < s.outlier_rate)
            if outlier:
                centre_px = self._rng.uniform((0.0, 0.0), (cam.width - 1, cam.height - 1))
            length = max(image.length + noise[2], 1.0)
            width = max(image.width + noise[3], 1.0)
            angle = image.angle
            if width > length:  # the noise turned a round outline: the long axis is the other
                length, width = width, length
                angle += 0.5 * math.pi if angle <= 0.0 else -0.5 * math.pi
            found.append(Detection(centre_px, float(length), float(width), angle, outlier))
        stamp = exposure + (self._rng.normal(0.0, s.stamp_jitter) if s.stamp_jitter else 0.0)
        return Frame(s.name, stamp, exposure, exposure + s.latency, tuple(found))

    def next_exposure(self) -> float:
        """Time of the next exposure [s]."""
        return self.spec.phase + self._next_k / self.spec.rate

    def expose(self, balls_at: BallsAt) -> None:
        """Take the next exposure and queue its frame."""
        t = self.next_exposure()
        self._next_k += 1
        centres, axes = balls_at(t)
        self.counts['frames'] += 1
        if len(self._queue) >= self.depth:
            self._queue.popleft()
            self.counts['queue_full'] += 1
        self._queue.append(self.frame(t, centres, axes))

    def deliver(self, now: float) -> list[Frame]:
        """Return the queued frames whose delivery time has come by ``now`` [s], oldest first."""
        out = []
        while self._queue and self._queue[0].delivery <= now + 1e-12:
            out.append(self._queue.popleft())
        self.counts['delivered'] += len(out)
        return out

    def step(self, now: float, balls_at: BallsAt) -> list[Frame]:
        """
        Expose every frame due up to ``now`` [s]; return the frames now delivered.

        Oldest first; ``balls_at`` is called with non-decreasing times.
        """
        while self.next_exposure() <= now + 1e-12:
            self.expose(balls_at)
        return self.deliver(now)


class RigSimulator:
    """
    Every camera of a rig (:class:`CameraSimulator` each).

    :meth:`step` exposes their frames in time order across the cameras, so that ``balls_at``
    is called with non-decreasing times.
    """

    def __init__(self, rig: tuple[RigCamera, ...], length: float, diameter: float) -> None:
        self.cameras = [CameraSimulator(spec, length, diameter) for spec in rig]

    def start(self, now: float) -> None:
        """Every camera's next exposure is its first after ``now`` [s]."""
        for cam in self.cameras:
            cam.start(now)

    def step(self, now: float, balls_at: BallsAt) -> list[Frame]:
        """Expose every frame due up to ``now`` [s]; return those delivered, oldest first."""
        while True:
            due = min(self.cameras, key=CameraSimulator.next_exposure)
            t = due.next_exposure()
            if t > now + 1e-12:
                break
            due.expose(balls_at)
        out = [f for cam in self.cameras for f in cam.deliver(now)]
        return sorted(out, key=lambda f: (f.delivery, f.camera))

    def flush(self) -> list[Frame]:
        """Return every frame still waiting (before its delivery time), oldest first."""
        out = [f for cam in self.cameras for f in cam.deliver(math.inf)]
        return sorted(out, key=lambda f: (f.delivery, f.camera))

    @property
    def counts(self) -> collections.Counter:
        """Return the cameras' counts added up."""
        return sum((cam.counts for cam in self.cameras), collections.Counter())


def simulate(
    rig: tuple[RigCamera, ...], balls_at: BallsAt, start: float, end: float,
    length: float, diameter: float,
) -> list[Frame]:
    """
    Return every frame of every camera exposed in (``start``, ``end``] [s].

    In delivery order: the whole flight offline, in strides that keep the queues from
    overflowing.
    """
    sim = RigSimulator(rig, length, diameter)
    sim.start(start)
    stride = 0.5 * QUEUE_DEPTH / max(spec.rate for spec in rig)
    frames, now = [], start
    while now < end:
        now = min(now + stride, end)
        frames += sim.step(now, balls_at)
    return frames + sim.flush()


def sampled_flight(times, positions, velocities, axes) -> BallsAt:
    """
    Return balls_at(t) of one ball sampled at ``times`` [s] (increasing).

    The centre by cubic Hermite interpolation of ``positions`` [m] and ``velocities`` [m/s],
    the axis linearly (renormalised); outside the samples, no ball.
    """
    times = np.asarray(times, dtype=float)
    positions, velocities = np.asarray(positions, float), np.asarray(velocities, float)
    axes = np.asarray(axes, dtype=float)

    def balls_at(t: float) -> tuple[np.ndarray, np.ndarray]:
        if not times[0] <= t <= times[-1]:
            return np.zeros((0, 3)), np.zeros((0, 3))
        i = min(int(np.searchsorted(times, t, side='right')) - 1, len(times) - 2)
        h = times[i + 1] - times[i]
        s = (t - times[i]) / h
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        p = (h00 * positions[i] + h10 * h * velocities[i] + h01 * positions[i + 1]
             + h11 * h * velocities[i + 1])
        a = (1 - s) * axes[i] + s * axes[i + 1]
        return p[None], (a / np.linalg.norm(a))[None]

    return balls_at
