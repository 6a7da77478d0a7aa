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
Frames and conversions: the one place for them (docs/physics.md, "Frames and signs").

World frame ``field`` (REP-103): x downfield, y to the thrower's left, z up. Body frame
``football``: x along the spin axis toward the leading nose, y and z transverse. The paper's
frame P (X downfield, Y up, Z right) maps as x = X, y = -Z, z = Y.

All functions accept arrays of shape (..., 3) (vectors) or (..., 4) (quaternions, ROS order
x, y, z, w) and broadcast over leading axes. Angles in radians.
"""

from __future__ import annotations

import numpy as np

FIELD_FRAME = 'field'
BODY_FRAME = 'football'
UP = np.array([0.0, 0.0, 1.0])
GRAVITY = 9.81
"""Magnitude of gravity [m/s^2], acting along -z in ``field``."""


def paper_to_field(vec_paper: np.ndarray) -> np.ndarray:
    """Map a vector from the paper frame (X downfield, Y up, Z right) to ``field``."""
    v = np.asarray(vec_paper, dtype=float)
    return np.stack([v[..., 0], -v[..., 2], v[..., 1]], axis=-1)


def field_to_paper(vec_field: np.ndarray) -> np.ndarray:
    """Map a vector from ``field`` to the paper frame (inverse of :func:`paper_to_field`)."""
    v = np.asarray(vec_field, dtype=float)
    return np.stack([v[..., 0], v[..., 2], -v[..., 1]], axis=-1)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def velocity_frame(velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return unit vectors e1 (along v), e2 (up, perpendicular to e1), e3 = e1 x e2 (right).

    In ``field``.

    Undefined for a vertical velocity.
    """
    e1 = _unit(np.asarray(velocity, dtype=float))
    up = np.broadcast_to(UP, e1.shape)
    e2 = _unit(up - np.sum(up * e1, axis=-1, keepdims=True) * e1)
    e3 = np.cross(e1, e2)
    return e1, e2, e3


def to_velocity_frame(vec: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """Return components (along e1, e2, e3) of a ``field`` vector in ``velocity``'s frame."""
    e1, e2, e3 = velocity_frame(velocity)
    vec = np.asarray(vec, dtype=float)
    return np.stack([np.sum(vec * e, axis=-1) for e in (e1, e2, e3)], axis=-1)


def from_velocity_frame(components: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """Return a ``field`` vector from velocity-frame components (inverse of to_velocity_frame)."""
    e1, e2, e3 = velocity_frame(velocity)
    c = np.asarray(components, dtype=float)
    return c[..., 0:1] * e1 + c[..., 1:2] * e2 + c[..., 2:3] * e3


def air_velocity(velocity: np.ndarray, wind=None) -> np.ndarray:
    """Air-relative velocity u = v - wind [m/s] in ``field`` (``velocity`` itself without wind)."""
    velocity = np.asarray(velocity, dtype=float)
    return velocity if wind is None else velocity - np.asarray(wind, dtype=float)


def aero_angles(axis: np.ndarray, velocity: np.ndarray, wind=None) -> np.ndarray:
    """
    Angle of attack alpha, sideslip beta and total angle delta [rad], stacked on the last axis.

    Against the air-relative velocity u = velocity - ``wind`` (both in ``field``, m/s):
    alpha = atan2(s.e2, s.e1) (nose above u > 0), beta = asin(s.e3) (nose right of u > 0),
    delta = acos(s.e1), with e1, e2, e3 the velocity frame of u.
    """
    s1, s2, s3 = np.moveaxis(to_velocity_frame(axis, air_velocity(velocity, wind)), -1, 0)
    alpha = np.arctan2(s2, s1)
    beta = np.arcsin(np.clip(s3, -1.0, 1.0))
    delta = np.arccos(np.clip(s1, -1.0, 1.0))
    return np.stack([alpha, beta, delta], axis=-1)


def axis_from_aero_angles(alpha, beta, velocity: np.ndarray) -> np.ndarray:
    """
    Return the unit axis in ``field`` with alpha and beta [rad] against ``velocity``.

    alpha, beta broadcast with the leading axes of ``velocity``.
    """
    alpha, beta = np.asarray(alpha, dtype=float), np.asarray(beta, dtype=float)
    comps = np.stack(
        [np.cos(beta) * np.cos(alpha), np.cos(beta) * np.sin(alpha), np.sin(beta)], axis=-1
    )
    return from_velocity_frame(comps, velocity)


def flight_path_angle(velocity: np.ndarray) -> np.ndarray:
    """Angle Phi of the velocity above the horizontal [rad]."""
    v = np.asarray(velocity, dtype=float)
    return np.arctan2(v[..., 2], np.hypot(v[..., 0], v[..., 1]))


def direction(speed, elevation, azimuth) -> np.ndarray:
    """
    Return velocity [m/s] in ``field`` from speed, elevation and azimuth [rad].

    Elevation above the horizontal, azimuth from +x toward +y, i.e. counter-clockwise seen from
    above; arrays broadcast to (..., 3).
    """
    speed, elevation, azimuth = (np.asarray(x, dtype=float) for x in (speed, elevation, azimuth))
    return speed[..., None] * np.stack(
        [
            np.cos(elevation) * np.cos(azimuth),
            np.cos(elevation) * np.sin(azimuth),
            np.sin(elevation),
        ],
        axis=-1,
    )


def quaternion_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Return the unit quaternion (x, y, z, w) of a 3x3 rotation matrix (columns = body axes)."""
    m = np.asarray(rot, dtype=float)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        k = 2.0 * np.sqrt(trace + 1.0)
        q = [(m[2, 1] - m[1, 2]) / k, (m[0, 2] - m[2, 0]) / k, (m[1, 0] - m[0, 1]) / k, 0.25 * k]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        k = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * k, (m[0, 1] + m[1, 0]) / k, (m[0, 2] + m[2, 0]) / k, (m[2, 1] - m[1, 2]) / k]
    elif m[1, 1] > m[2, 2]:
        k = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / k, 0.25 * k, (m[1, 2] + m[2, 1]) / k, (m[0, 2] - m[2, 0]) / k]
    else:
        k = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / k, (m[1, 2] + m[2, 1]) / k, 0.25 * k, (m[1, 0] - m[0, 1]) / k]
    q = np.array(q)
    return q / np.linalg.norm(q)


def quaternion_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of quaternions (..., 4) in (x, y, z, w) order."""
    q = np.asarray(q, dtype=float)
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def body_x_axis(q: np.ndarray) -> np.ndarray:
    """Body x axis (the spin axis) in ``field`` of quaternions (..., 4) in (x, y, z, w) order."""
    return quaternion_to_matrix(q)[..., :, 0]


def attitude_with_axis(axis: np.ndarray) -> np.ndarray:
    """
    Quaternion (x, y, z, w) whose body x is ``axis`` and body z is as close to up as it can be.

    Body y = z x x points to the left of the axis (REP-103). For a vertical axis, +x of
    ``field`` stands in for up.
    """
    x_b = _unit(np.asarray(axis, dtype=float))
    ref = UP if abs(x_b[2]) < 0.999 else np.array([1.0, 0.0, 0.0])
    z_b = _unit(ref - np.dot(ref, x_b) * x_b)
    y_b = np.cross(z_b, x_b)
    return quaternion_from_matrix(np.column_stack([x_b, y_b, z_b]))
