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
A calibrated pinhole camera as sensor_msgs/CameraInfo defines it, and the ball's image in it.

Intrinsics: ``K`` (3x3, of the raw, distorted image), ``D`` (``plumb_bob``: k1, k2, p1, p2, k3;
``rational_polynomial``: k1, k2, p1, p2, k3, k4, k5, k6; an empty D means no distortion), ``R``
(3x3, the rectifying rotation) and ``P`` (3x4, the rectified image's projection). A point
(X, Y, Z) in the camera's optical frame (z forward, x right, y down) has normalised coordinates
x = X / Z, y = Y / Z; the lens moves them to

    x' = x c + 2 p1 x y + p2 (r^2 + 2 x^2),   y' = y c + p1 (r^2 + 2 y^2) + 2 p2 x y,
    c = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6),   r^2 = x^2 + y^2,

and the raw pixel is K (x', y', 1) (u right, v down, pixels; the centre of the top-left pixel
at (0, 0) as OpenCV counts). :meth:`Camera.unproject` inverts the lens by Newton's method;
:meth:`Camera.rectify` maps raw pixels to the rectified image (P[:, :3] R applied to the ray),
as OpenCV's ``undistortPoints`` with R and P does. Points beyond the radius where the lens
model folds back (x' stops growing with x) are outside the camera's view.

The pose of the optical frame in ``field``: ``rotation`` (3x3, columns = the optical axes in
``field``) and ``position`` [m]; p_cam = rotation^T (p_field - position).

The ball's image (:func:`ball_image`): the outline of a prolate spheroid (length L along its
spin axis, diameter D across) is the conic M Q* M^T of its dual quadric Q*, exact in normalised
coordinates; the lens is applied to it to first order about the outline's centre (the ball
spans a few pixels to a few tens: the lens's curvature across it is far below a pixel).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

DISTORTION_MODELS = {'plumb_bob': 5, 'rational_polynomial': 8}
"""CameraInfo distortion models this module implements, and their number of coefficients."""
NEWTON_ITERATIONS = 50
"""Most Newton steps of the lens inversion (a few suffice inside the view)."""
MIN_DEPTH = 1e-6
"""Points nearer than this in front of the camera [m] are behind it (not projected)."""


def _matrix(name: str, value, shape: tuple[int, int]) -> np.ndarray:
    m = np.asarray(value, dtype=float)
    if m.size != shape[0] * shape[1]:
        raise ValueError(f"camera '{name}' must have {shape[0] * shape[1]} numbers, got {m.size}")
    m = m.reshape(shape)
    if not np.all(np.isfinite(m)):
        raise ValueError(f"camera '{name}' must be finite")
    return m


def _rotation(name: str, value) -> np.ndarray:
    m = _matrix(name, value, (3, 3))
    if not np.allclose(m @ m.T, np.eye(3), atol=1e-6) or np.linalg.det(m) < 0.0:
        raise ValueError(f"camera '{name}' must be a rotation matrix (orthonormal, det +1)")
    return m


@dataclass(frozen=True)
class Camera:
    """
    One calibrated camera: CameraInfo's fields and the pose of its optical frame.

    width, height [px], distortion model, D, K, R, P; the pose in ``field``: ``rotation``
    (3x3, columns = the optical axes) and ``position`` [m]. Every field is checked on
    construction (ValueError naming it).
    """

    width: int
    height: int
    K: np.ndarray
    D: np.ndarray | tuple = ()
    distortion_model: str = 'plumb_bob'
    R: np.ndarray | tuple = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    P: np.ndarray | None = None
    rotation: np.ndarray | tuple = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    position: np.ndarray | tuple = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        for name in ('width', 'height'):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not (
                1 <= value <= 100_000
            ):
                raise ValueError(
                    f"camera '{name}' must be an integer in [1, 100000], got {value!r}"
                )
        if self.distortion_model not in DISTORTION_MODELS:
            raise ValueError(
                f"camera 'distortion_model' must be one of {sorted(DISTORTION_MODELS)}, "
                f'got {self.distortion_model!r}'
            )
        K = _matrix('K', self.K, (3, 3))
        if K[0, 0] <= 0.0 or K[1, 1] <= 0.0 or K[1, 0] or K[2, 0] or K[2, 1] or K[2, 2] != 1.0:
            raise ValueError(
                "camera 'K' must be [fx, s, cx, 0, fy, cy, 0, 0, 1] with fx, fy > 0"
            )
        d = np.asarray(self.D, dtype=float).ravel()
        n = DISTORTION_MODELS[self.distortion_model]
        if d.size not in (0, n) or not np.all(np.isfinite(d)):
            raise ValueError(
                f"camera 'D' must hold 0 or {n} finite numbers for {self.distortion_model}, "
                f'got {d.size}'
            )
        coeffs = np.zeros(8)
        coeffs[: d.size] = d
        P = np.column_stack([K, np.zeros(3)]) if self.P is None else _matrix('P', self.P, (3, 4))
        if not abs(np.linalg.det(P[:, :3])) > 1e-12 or np.linalg.cond(P[:, :3]) > 1e12:
            raise ValueError("camera 'P' must have an invertible left 3x3 block")
        position = np.asarray(self.position, dtype=float).ravel()
        if position.size != 3 or not np.all(np.isfinite(position)):
            raise ValueError("camera 'position' must be 3 finite numbers [m]")
        for name, value in (
            ('K', K), ('D', d), ('R', _rotation('R', self.R)), ('P', P),
            ('rotation', _rotation('rotation', self.rotation)), ('position', position),
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, '_coeffs', coeffs)
        object.__setattr__(self, '_r2_max', _fold_radius(coeffs))

    # --- the lens ---------------------------------------------------------------------------
    def distort(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the lens's image (..., 2) of normalised points ``xy`` (..., 2), and its Jacobian.

        The Jacobian (..., 2, 2) is d(x', y') / d(x, y).
        """
        k1, k2, p1, p2, k3, k4, k5, k6 = self._coeffs
        x, y = xy[..., 0], xy[..., 1]
        r2 = x * x + y * y
        num = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        den = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6))
        radial = num / den
        dnum = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
        dden = k4 + r2 * (2.0 * k5 + 3.0 * k6 * r2)
        g = (dnum * den - num * dden) / (den * den)  # d radial / d r^2
        out = np.stack(
            [
                x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
            ],
            axis=-1,
        )
        jac = np.empty(xy.shape[:-1] + (2, 2))
        jac[..., 0, 0] = radial + 2.0 * x * x * g + 2.0 * p1 * y + 6.0 * p2 * x
        jac[..., 0, 1] = 2.0 * x * y * g + 2.0 * p1 * x + 2.0 * p2 * y
        jac[..., 1, 0] = 2.0 * x * y * g + 2.0 * p1 * x + 2.0 * p2 * y
        jac[..., 1, 1] = radial + 2.0 * y * y * g + 6.0 * p1 * y + 2.0 * p2 * x
        return out, jac

    def undistort(self, xy_distorted: np.ndarray) -> np.ndarray:
        """Invert :meth:`distort` by Newton's method from the distorted point (..., 2)."""
        target = np.asarray(xy_distorted, dtype=float)
        xy = target.copy()
        for _ in range(NEWTON_ITERATIONS):
            out, jac = self.distort(xy)
            step = np.linalg.solve(jac, (target - out)[..., None])[..., 0]
            xy = xy + step
            if np.all(np.abs(step) < 1e-15):
                break
        return xy

    # --- pixels -----------------------------------------------------------------------------
    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """Points (..., 3) [m] in ``field`` -> the optical frame."""
        return (np.asarray(points, dtype=float) - self.position) @ self.rotation

    def project_camera(self, points_cam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the raw pixels (..., 2) of points (..., 3) in the optical frame, and the Jacobian.

        The Jacobian (..., 2, 3) is d(u, v) / d(point) [px/m]. Points behind the camera give
        NaN.
        """
        p = np.asarray(points_cam, dtype=float)
        z = np.where(p[..., 2] > MIN_DEPTH, p[..., 2], np.nan)
        xy = p[..., :2] / z[..., None]
        out, jd = self.distort(xy)
        k2 = self.K[:2, :2]
        pixels = out @ k2.T + self.K[:2, 2]
        jn = np.zeros(p.shape[:-1] + (2, 3))
        jn[..., 0, 0] = jn[..., 1, 1] = 1.0 / z
        jn[..., 0, 2] = -xy[..., 0] / z
        jn[..., 1, 2] = -xy[..., 1] / z
        return pixels, k2 @ jd @ jn

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the raw pixels (..., 2) of points (..., 3) [m] in ``field``, and the Jacobian.

        The Jacobian (..., 2, 3) is d(u, v) / d(point in field) [px/m]. NaN for points behind
        the camera.
        """
        pixels, jac = self.project_camera(self.to_camera(points))
        return pixels, jac @ self.rotation.T

    def image_width(self, points: np.ndarray, diameter: float) -> np.ndarray:
        """
        Return the apparent diameter [px] (...,) of a sphere of ``diameter`` [m] at ``points``.

        In ``field``; to first order in diameter / distance the sphere's outline is the image of
        its disc across the line of sight, an ellipse of axes D s_min and D s_max (s the
        singular values [px/m] of the projection's Jacobian on that disc: off the optical axis
        the radial one is stretched by 1 / cos of the angle, the lens scales both): D sqrt(s_min
        s_max), their geometric mean (:meth:`width_spread` their spread). NaN behind the camera.
        """
        s_min, s_max = self._disc_scales(points)
        return diameter * np.sqrt(s_min * s_max)

    def width_spread(self, points: np.ndarray) -> np.ndarray:
        """
        Return (s_max - s_min) / (s_max + s_min) [1] (...,) of :meth:`image_width` at ``points``.

        The short axis of a spheroid's outline lies between D s_min and D s_max, by its attitude:
        about this fraction of the width either side of :meth:`image_width`.
        """
        s_min, s_max = self._disc_scales(points)
        return (s_max - s_min) / (s_max + s_min)

    def _disc_scales(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Singular values [px/m] (...,) of the projection on the disc across the line of sight."""
        p = self.to_camera(points)
        p = np.where((p[..., 2] > MIN_DEPTH)[..., None], p, np.nan)
        _, jac = self.project_camera(p)
        u = p / np.linalg.norm(p, axis=-1, keepdims=True)
        m = jac @ jac.swapaxes(-1, -2) - (jac @ u[..., None]) @ (jac @ u[..., None]).swapaxes(
            -1, -2
        )  # J (I - u u') J'
        tr = m[..., 0, 0] + m[..., 1, 1]
        det = np.abs(m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0])
        gap = np.sqrt(np.maximum(0.25 * tr**2 - det, 0.0))
        return np.sqrt(np.maximum(0.5 * tr - gap, 0.0)), np.sqrt(0.5 * tr + gap)

    def unproject(self, pixels: np.ndarray) -> np.ndarray:
        """Return the normalised rays (..., 3) (x, y, 1) in the optical frame of raw pixels."""
        uv = np.asarray(pixels, dtype=float)
        yd = (uv[..., 1] - self.K[1, 2]) / self.K[1, 1]
        xd = (uv[..., 0] - self.K[0, 2] - self.K[0, 1] * yd) / self.K[0, 0]
        xy = self.undistort(np.stack([xd, yd], axis=-1))
        return np.concatenate([xy, np.ones(xy.shape[:-1] + (1,))], axis=-1)

    def rectify(self, pixels: np.ndarray) -> np.ndarray:
        """Return the rectified-image pixels (..., 2) of raw pixels (..., 2) (through R and P)."""
        rays = self.unproject(pixels) @ (self.P[:, :3] @ self.R).T
        return rays[..., :2] / rays[..., 2:3]

    def in_view(self, points: np.ndarray) -> np.ndarray:
        """
        Tell which points (..., 3) in ``field`` the camera images.

        In front, inside the lens model's unfolded radius and inside the image
        (0 <= u <= width - 1, the same for v).
        """
        p = self.to_camera(points)
        with np.errstate(invalid='ignore', divide='ignore'):
            front = p[..., 2] > MIN_DEPTH
            r2 = (p[..., 0] ** 2 + p[..., 1] ** 2) / np.where(front, p[..., 2], 1.0) ** 2
            pixels = self.project_camera(p)[0]
        inside = (
            (pixels[..., 0] >= 0.0) & (pixels[..., 0] <= self.width - 1)
            & (pixels[..., 1] >= 0.0) & (pixels[..., 1] <= self.height - 1)
        )
        return front & (r2 < self._r2_max) & inside


def _fold_radius(coeffs: np.ndarray) -> float:
    """r^2 where the radial map r -> r radial(r^2) first stops growing (inf if it never does)."""
    k1, k2, _, _, k3, k4, k5, k6 = coeffs
    r = np.linspace(0.0, 20.0, 20001)[1:]
    r2 = r * r
    rd = r * (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)))
    with np.errstate(invalid='ignore'):
        bad = ~(np.diff(rd) > 0.0) | ~np.isfinite(rd[1:])
    return float(r2[np.argmax(bad)]) if bad.any() else math.inf


@dataclass(frozen=True)
class BallImage:
    """
    The ball as a camera images it (raw pixels).

    ``center`` (2,) the pixel of the ball's centre; ``length`` and ``width`` [px] the long and
    short axes (full lengths) of its outline's ellipse; ``angle`` [rad] the long axis's angle
    from +u toward +v, in (-pi/2, pi/2]; ``box`` (u_min, v_min, u_max, v_max) the outline's
    axis-aligned bounding box [px].
    """

    center: np.ndarray
    length: float
    width: float
    angle: float
    box: np.ndarray


def spheroid_dual(
    center: np.ndarray, axis: np.ndarray, length: float, diameter: float
) -> np.ndarray:
    """
    Return the dual quadric (4x4) of a prolate spheroid in ``field``.

    Its centre [m], unit long ``axis``, full ``length`` along it and ``diameter`` across [m].
    """
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    a2, b2 = (0.5 * length) ** 2, (0.5 * diameter) ** 2
    shape = b2 * np.eye(3) + (a2 - b2) * np.outer(axis, axis)
    c = np.asarray(center, dtype=float)
    q = np.empty((4, 4))
    q[:3, :3] = shape - np.outer(c, c)
    q[:3, 3] = q[3, :3] = -c
    q[3, 3] = -1.0
    return q


def ball_image(
    camera: Camera, center: np.ndarray, axis: np.ndarray, length: float, diameter: float
) -> BallImage | None:
    """
    Return the image of a prolate spheroid; None unless the whole ball is in front.

    Its centre [m] and unit ``axis`` in ``field``, full ``length`` and ``diameter`` [m].
    """
    c_cam = camera.to_camera(center)
    if not c_cam[2] > 0.5 * max(length, diameter) + MIN_DEPTH:
        return None
    m = np.column_stack([camera.rotation.T, -camera.rotation.T @ camera.position])
    dual = m @ spheroid_dual(center, axis, length, diameter) @ m.T  # dual conic, normalised
    x0 = dual[:2, 2] / dual[2, 2]
    shape = np.outer(x0, x0) - dual[:2, :2] / dual[2, 2]  # (x - x0)^T shape^-1 (x - x0) = 1
    out, jd = camera.distort(x0)
    jac = camera.K[:2, :2] @ jd
    s = jac @ shape @ jac.T
    values, vectors = np.linalg.eigh(0.5 * (s + s.T))
    if not values[0] > 0.0:
        return None
    angle = math.atan2(vectors[1, 1], vectors[0, 1])
    if angle <= -0.5 * math.pi:
        angle += math.pi
    elif angle > 0.5 * math.pi:
        angle -= math.pi
    mid = out @ camera.K[:2, :2].T + camera.K[:2, 2]
    half = np.sqrt(np.diag(s))
    pixel = camera.project_camera(c_cam)[0]
    return BallImage(
        pixel, 2.0 * math.sqrt(values[1]), 2.0 * math.sqrt(values[0]), angle,
        np.concatenate([mid - half, mid + half]),
    )
