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
Simulated ball detections of a rig's cameras (:mod:`.rig`): what a detector on each camera
would report, seeded so that runs repeat.

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
    One exposure of one camera: its ``stamp`` (exposure time with jitter) [s], true
    ``exposure`` time [s], ``delivery`` time [s] and ``detections``.
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
            found.append(Detection(
                centre_px, float(max(image.length + noise[2], 1.0)),
                float(max(image.width + noise[3], 1.0)),
                image.angle, outlier,
            ))
        stamp = exposure + (self._rng.normal(0.0, s.stamp_jitter) if s.stamp_jitter else 0.0)
        return Frame(s.name, stamp, exposure, exposure + s.latency, tuple(found))

    def step(self, now: float, balls_at: BallsAt) -> list[Frame]:
        """
        Expose every frame due up to ``now`` [s] and return the frames now delivered (oldest
        first). ``balls_at`` is called with non-decreasing times.
        """
        s = self.spec
        while True:
            t = s.phase + self._next_k / s.rate
            if t > now + 1e-12:
                break
            self._next_k += 1
            centres, axes = balls_at(t)
            self.counts['frames'] += 1
            if len(self._queue) >= self.depth:
                self._queue.popleft()
                self.counts['queue_full'] += 1
            self._queue.append(self.frame(t, centres, axes))
        out = []
        while self._queue and self._queue[0].delivery <= now + 1e-12:
            out.append(self._queue.popleft())
        return out


def simulate(
    rig: tuple[RigCamera, ...], balls_at: BallsAt, start: float, end: float,
    length: float, diameter: float,
) -> list[Frame]:
    """
    Return every frame of every camera exposed in (``start``, ``end``] [s], in delivery order
    (the whole flight offline: nothing waits in a queue).
    """
    frames = []
    for spec in rig:
        sim = CameraSimulator(spec, length, diameter)
        sim.start(start)
        k = sim._next_k
        while spec.phase + k / spec.rate <= end + 1e-12:
            t = spec.phase + k / spec.rate
            centres, axes = balls_at(t)
            frames.append(sim.frame(t, centres, axes))
            k += 1
    frames.sort(key=lambda f: (f.delivery, f.camera))
    return frames


def sampled_flight(times, positions, velocities, axes) -> BallsAt:
    """
    Return balls_at(t) of one ball sampled at ``times`` [s] (increasing): the centre by cubic
    Hermite interpolation of ``positions`` [m] and ``velocities`` [m/s], the axis linearly
    (renormalised); outside the samples, no ball.
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
