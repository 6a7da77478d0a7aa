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
Camera detections as the tracker's measurements: pixels fused directly, no triangulation.

A detection of camera ``camera`` (:class:`.camera.Camera`) is its ball's centre pixel (u, v)
and apparent width w [px] (the outline's short axis). Once a throw runs, it is a
:class:`.measurement.ProjectedFix` of z = (u, v, w): (u, v) the projection of the ball's
centre (``pixel_noise`` [px] 1 sigma each), w = f D / Z its apparent diameter (f the lens's
local scale, Z the depth: :meth:`.camera.Camera.image_width`; ``pixel_noise``,
:data:`WIDTH_MODEL` of w and the attitude's share of the outline's stretch off the optical axis
in quadrature: :func:`width_sigma`), so one camera alone measures range too. The filter's
unscented update and the batch fit take it as they take a position; gating is in pixel space
(the innovation's Mahalanobis distance). Before a throw runs, the detection is a position fix:
the ray through (u, v) at depth Z = f D / w, its covariance from the same noises (metres along
the ray at long range: enough to find the arc; the pixels then take over). Several cameras,
unsynchronised: each detection is its own fix at its own stamp.
"""

from __future__ import annotations

import math

import numpy as np

from .camera import Camera
from .measurement import PositionFix, ProjectedFix

WIDTH_MODEL = 0.03
"""Relative error [1] of w = f D / Z as the width of a spheroid's outline (1 sigma)."""
MIN_WIDTH = 1.0
"""Narrowest apparent width [px] taken (a detector's box is at least a pixel)."""


def check_detection(camera: Camera, center, width: float) -> str | None:
    """Return why a detection (centre (2,) [px], width [px]) is refused, or None."""
    try:
        c = np.asarray(center, dtype=float).reshape(2)
        w = float(width)
    except (TypeError, ValueError):
        return 'the centre must be 2 numbers and the width a number'
    if not (np.all(np.isfinite(c)) and math.isfinite(w)):
        return 'non-finite centre or size'
    if not (-0.5 <= c[0] <= camera.width - 0.5 and -0.5 <= c[1] <= camera.height - 0.5):
        size = f'{camera.width}x{camera.height}'
        return f'centre ({c[0]:.1f}, {c[1]:.1f}) px outside the {size} image'
    if not MIN_WIDTH <= w <= max(camera.width, camera.height):
        return f'width {w:g} px outside [{MIN_WIDTH:g}, image size]'
    return None


def width_sigma(camera: Camera, center, width: float, noise: float) -> float:
    """
    Return the 1-sigma noise [px] of a detection's apparent width w [px].

    The detector's ``noise`` [px], :data:`WIDTH_MODEL` w and the spheroid's attitude: its
    outline's short axis lies within +/- :meth:`.camera.Camera.width_spread` w of the model
    (uniform, at the ray through the centre (2,) [px]), in quadrature.
    """
    ray = camera.rotation @ camera.unproject(np.asarray(center, dtype=float).reshape(2))
    return _width_sigma(camera, camera.position + ray, float(width), noise)


def _width_sigma(camera: Camera, point: np.ndarray, width: float, noise: float) -> float:
    """:func:`width_sigma` with the centre's ray given by a ``point`` (3,) [m, field] on it."""
    spread = float(camera.width_spread(point))
    return math.sqrt(noise**2 + (WIDTH_MODEL * width) ** 2 + (spread * width) ** 2 / 3.0)


def pixel_fix(
    camera: Camera, center, width: float, noise: float, diameter: float, source=None
) -> ProjectedFix:
    """
    Return the detection as a :class:`ProjectedFix` of (u, v, w) [px] (module docstring).

    ``source``: the camera's name (:class:`.measurement.Measurement`).
    """
    w = float(width)
    cov = np.diag([noise**2, noise**2, width_sigma(camera, center, w, noise) ** 2])

    def project(points: np.ndarray) -> np.ndarray:
        uv = camera.project(points)[0]
        return np.column_stack([uv, camera.image_width(points, diameter)])

    z = np.array([float(center[0]), float(center[1]), w])
    return ProjectedFix(z, cov, source, project)


def range_fix(
    camera: Camera, center, width: float, noise: float, diameter: float, source=None
) -> PositionFix:
    """
    Return the detection as a :class:`PositionFix` in ``field``: the ray at depth f D / w [m].

    Its covariance: the depth's (from the width's noise) along the ray, the centre's across;
    ``source`` the camera's name (:class:`.measurement.Measurement`).
    """
    ray = camera.unproject(np.asarray(center, dtype=float))
    point = camera.position + camera.rotation @ ray  # on the ray at Z = 1
    scale = float(camera.image_width(point, 1.0))
    w = float(width)
    depth = scale * diameter / w
    sigma_w = _width_sigma(camera, point, w, noise)
    p_cam = ray * depth
    # d p_cam / d(depth) = ray; across the ray: noise / scale per unit depth
    across = noise / scale * depth
    cov_cam = (depth * sigma_w / w) ** 2 * np.outer(ray, ray) + across**2 * (
        np.eye(3) - np.outer(ray, ray) / float(ray @ ray)
    )
    rot = camera.rotation
    return PositionFix(rot @ p_cam + camera.position, rot @ cov_cam @ rot.T, source)


class CameraFusion:
    """
    Feed camera detections to a tracker.

    A :class:`.multi.MultiTracker` or :class:`.tracker.FlightTracker` (anything with
    ``observe(stamp, meas, now)``).

    ``noise`` [px] 1 sigma of a detection's centre and width; ``diameter`` [m] of the ball.
    :attr:`counts` tells what became of the detections ('refused', 'pixels', 'range').
    """

    def __init__(self, tracker, noise: float, diameter: float) -> None:
        self.tracker, self.noise, self.diameter = tracker, float(noise), float(diameter)
        self.counts: dict[str, int] = {'refused': 0, 'pixels': 0, 'range': 0}

    def observe(self, stamp: float, camera: Camera, center, width: float, now=None,
                source=None):
        """
        Process one detection taken at ``stamp`` [s]; return the tracker's answer.

        ``source``: the camera's name, whose stamps' jitter is measured apart from the other
        cameras' (None: the ``camera`` object's identity).

        As pixels; when no live throw can take them (a 'candidate': pixels cannot start a
        throw, nor start a lost one again), as a range fix instead, which can. A refused
        detection gives (None, reason)
        and counts 'refused'.
        """
        why = check_detection(camera, center, width)
        source = id(camera) if source is None else source
        if why is None:
            try:
                meas = pixel_fix(camera, center, width, self.noise, self.diameter, source)
            except ValueError as exc:
                why = str(exc)
        if why is not None:
            self.counts['refused'] += 1
            return None, why
        answer = self.tracker.observe(stamp, meas, now)
        result = answer[1] if isinstance(answer, tuple) else answer
        if result.status != 'candidate':  # taken, or refused by a live throw's gate
            self.counts['pixels'] += 1
            return answer
        try:
            fix = range_fix(camera, center, width, self.noise, self.diameter, source)
        except ValueError as exc:  # a ball so small that its range means nothing
            self.counts['refused'] += 1
            return None, f'no range from a {float(width):g} px width: {exc}'
        self.counts['range'] += 1
        return self.tracker.observe(stamp, fix, now)
