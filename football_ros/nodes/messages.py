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
Message building: the one place where physics samples become ROS messages.

Frames: header.frame_id is the world frame (``field`` by default); Odometry.child_frame_id is
the body frame (``football``). The aero angles are not a vector: their header.frame_id is empty
(``ANGLES_FRAME``), which tf2 refuses to transform. All values are SI (m, m/s, rad, rad/s).
"""

from __future__ import annotations

import math
import struct
from typing import Iterable, Mapping, Sequence, TYPE_CHECKING

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import (
    Point,
    Pose,
    PoseStamped,
    Quaternion,
    Twist,
    Vector3,
    Vector3Stamped,
)
from nav_msgs.msg import Odometry
import numpy as np
from sensor_msgs.msg import CameraInfo
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from ..physics.frames import quaternion_from_matrix

if TYPE_CHECKING:  # type hints only: the command-line tools start without the compiled kernels
    from ..physics.flight import BallSample

try:  # the real tf2_msgs on a Jazzy install; pip_ros/tf2_msgs built by setup.sh on the pip ROS
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
except ImportError:  # pragma: no cover - no TF without tf2_msgs
    TFMessage = None

try:  # the real vision_msgs on a Jazzy install; pip_ros/vision_msgs built by setup.sh on pip ROS
    from vision_msgs.msg import (
        BoundingBox2D, Detection2D, Detection2DArray, ObjectHypothesisWithPose,
    )
except ImportError:  # pragma: no cover - no camera topics without vision_msgs
    Detection2DArray = None

ANGLES_FRAME = ''
"""header.frame_id of football/aero_angles(_linear): angles are no vector of any frame, and
tf2 refuses an empty frame id ("frame_ids cannot be empty") instead of rotating them."""
MAX_TRAIL_POINTS = 1000
"""Most points one trail marker carries; a longer trail is decimated (msg_docs/markers.md)."""

LEVELS = {
    'OK': DiagnosticStatus.OK,
    'WARN': DiagnosticStatus.WARN,
    'ERROR': DiagnosticStatus.ERROR,
    'STALE': DiagnosticStatus.STALE,
}


def time_msg(nanoseconds: int) -> Time:
    """builtin_interfaces/Time from integer nanoseconds."""
    sec, nanosec = divmod(int(nanoseconds), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def header(stamp: Time, frame_id: str) -> Header:
    return Header(stamp=stamp, frame_id=frame_id)


def point(v: Sequence[float]) -> Point:
    """geometry_msgs/Point from 3 numbers [m]."""
    return Point(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def vector3(v: Sequence[float]) -> Vector3:
    """geometry_msgs/Vector3 from 3 numbers."""
    return Vector3(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def quaternion(q: Sequence[float]) -> Quaternion:
    """geometry_msgs/Quaternion from (x, y, z, w)."""
    return Quaternion(x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def pose_of(position: Sequence[float], orientation: Sequence[float]) -> Pose:
    """geometry_msgs/Pose: position [m] and orientation (x, y, z, w)."""
    return Pose(position=point(position), orientation=quaternion(orientation))


def twist_of(linear: Sequence[float], angular: Sequence[float]) -> Twist:
    """geometry_msgs/Twist: linear [m/s] and angular [rad/s] velocity (frame: the caller's)."""
    return Twist(linear=vector3(linear), angular=vector3(angular))


def odometry(sample: BallSample, stamp: Time, frame_id: str, child_frame_id: str) -> Odometry:
    """
    Pose in ``frame_id``.

    Twist (linear and angular velocity) in the body frame ``child_frame_id``, as
    nav_msgs/Odometry specifies. Covariances are zero (exact model).
    """
    msg = Odometry(header=header(stamp, frame_id), child_frame_id=child_frame_id)
    msg.pose.pose.position = point(sample.position)
    msg.pose.pose.orientation = quaternion(sample.orientation)
    msg.twist.twist.linear = vector3(to_body_frame(sample.orientation, sample.velocity))
    msg.twist.twist.angular = vector3(to_body_frame(sample.orientation, sample.angular_velocity))
    return msg


def to_body_frame(q: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    """
    Components in the body frame of a world vector ``v`` (R(q)^T v), with plain floats.

    This runs for every Odometry message, where numpy's per-call overhead would dominate.
    """
    x, y, z, w = (-float(q[0]), -float(q[1]), -float(q[2]), float(q[3]))  # conjugate
    vx, vy, vz = float(v[0]), float(v[1]), float(v[2])
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + y * tz - z * ty,
        vy + w * ty + z * tx - x * tz,
        vz + w * tz + x * ty - y * tx,
    )


def tf_message(sample: BallSample, stamp: Time, frame_id: str, child_frame_id: str):
    """
    tf2_msgs/TFMessage with one transform.

    The body frame ``child_frame_id`` in the world frame ``frame_id`` (translation = ball
    centre [m], rotation = orientation, as the pose).
    """
    transform = TransformStamped(header=header(stamp, frame_id), child_frame_id=child_frame_id)
    transform.transform.translation = vector3(sample.position)
    transform.transform.rotation = quaternion(sample.orientation)
    return TFMessage(transforms=[transform])


def camera_info(camera, stamp: Time, frame_id: str):
    """sensor_msgs/CameraInfo of a :class:`~football_ros.estimation.camera.Camera`."""
    return CameraInfo(
        header=header(stamp, frame_id),
        width=int(camera.width),
        height=int(camera.height),
        distortion_model=camera.distortion_model,
        d=[float(v) for v in camera.D],
        k=[float(v) for v in camera.K.ravel()],
        r=[float(v) for v in camera.R.ravel()],
        p=[float(v) for v in camera.P.ravel()],
    )


def detection_array(detections, stamp: Time, frame_id: str, class_id: str):
    """
    vision_msgs/Detection2DArray of ball detections.

    Of :class:`~football_ros.estimation.detections.Detection`: bbox centre = the ball's centre
    pixel, theta = the outline's long-axis angle [rad], size_x / size_y = its long / short
    axis [px]; one hypothesis ``class_id``, score 1.
    """
    head = header(stamp, frame_id)
    out = Detection2DArray(header=head)
    for d in detections:
        box = BoundingBox2D(size_x=float(d.length), size_y=float(d.width))
        box.center.position.x, box.center.position.y = float(d.center[0]), float(d.center[1])
        box.center.theta = float(d.angle)
        hypothesis = ObjectHypothesisWithPose()
        hypothesis.hypothesis.class_id, hypothesis.hypothesis.score = class_id, 1.0
        out.detections.append(Detection2D(header=head, results=[hypothesis], bbox=box))
    return out


def static_transforms(poses, stamp: Time, frame_id: str):
    """tf2_msgs/TFMessage of (child_frame_id, rotation 3x3, position [m]) in ``frame_id``."""
    transforms = []
    for child, rotation, position in poses:
        t = TransformStamped(header=header(stamp, frame_id), child_frame_id=child)
        t.transform.translation = vector3(position)
        t.transform.rotation = quaternion(quaternion_from_matrix(rotation))
        transforms.append(t)
    return TFMessage(transforms=transforms)


def key_values(values: Mapping[str, object]) -> list[KeyValue]:
    """Build a KeyValue list; floats with full precision (repr), bools as 'true'/'false'."""
    out = []
    for key, value in values.items():
        if isinstance(value, bool):
            text = 'true' if value else 'false'
        elif isinstance(value, float):
            text = repr(value)
        else:
            text = str(value)
        out.append(KeyValue(key=str(key), value=text))
    return out


def diagnostic_status(
    name: str,
    level: str,
    message: str,
    values: Mapping[str, object],
    hardware_id: str = 'football_ros',
) -> DiagnosticStatus:
    return DiagnosticStatus(
        level=LEVELS[level],
        name=name,
        message=message,
        hardware_id=hardware_id,
        values=key_values(values),
    )


def level_of(status: DiagnosticStatus) -> str:
    """'OK', 'WARN', 'ERROR' or 'STALE' of a DiagnosticStatus (rclpy gives the level as bytes)."""
    value = status.level
    number = value[0] if isinstance(value, (bytes, bytearray)) else int(value)
    return {ord(v) if isinstance(v, bytes) else v: k for k, v in LEVELS.items()}[number]


def _color(r: float, g: float, b: float, a: float = 1.0) -> ColorRGBA:
    return ColorRGBA(r=r, g=g, b=b, a=a)


def markers(
    sample: BallSample,
    trail: Iterable[Point],
    stamp: Time,
    frame_id: str,
    ball_length: float,
    ball_diameter: float,
    namespace: str = 'football',
) -> MarkerArray:
    """
    Build the RViz markers.

    Ball (ellipsoid), spin-axis arrow (red), velocity arrow (green, 0.1 s of flight long),
    trail (line strip of the given past positions, geometry_msgs/Point).
    """
    hdr = header(stamp, frame_id)
    ball = Marker(header=hdr, ns=namespace, id=0, type=Marker.SPHERE, action=Marker.ADD)
    ball.pose.position = point(sample.position)
    ball.pose.orientation = quaternion(sample.orientation)
    ball.scale = vector3([ball_length, ball_diameter, ball_diameter])
    ball.color = _color(0.55, 0.27, 0.07)
    axis = Marker(header=hdr, ns=namespace, id=1, type=Marker.ARROW, action=Marker.ADD)
    axis.points = [point(sample.position), point(sample.position + 0.5 * sample.axis)]
    axis.scale = vector3([0.02, 0.04, 0.06])
    axis.color = _color(0.9, 0.1, 0.1)
    velocity = Marker(header=hdr, ns=namespace, id=2, type=Marker.ARROW, action=Marker.ADD)
    velocity.points = [point(sample.position), point(sample.position + 0.1 * sample.velocity)]
    velocity.scale = vector3([0.02, 0.04, 0.06])
    velocity.color = _color(0.1, 0.8, 0.1)
    path = Marker(header=hdr, ns=namespace, id=3, type=Marker.LINE_STRIP, action=Marker.ADD)
    path.points = list(trail)
    path.scale = vector3([0.03, 0.0, 0.0])
    path.color = _color(0.2, 0.4, 1.0, 0.8)
    for marker in (axis, velocity, path):  # points are in the header frame: identity pose
        marker.pose.orientation.w = 1.0
    return MarkerArray(markers=[ball, axis, velocity, path])


def decimated(points: Sequence[Point], first_index: int, limit: int = MAX_TRAIL_POINTS) -> list:
    """
    At most ``limit`` of ``points`` (oldest first), the newest always included.

    ``first_index`` is the running index of ``points[0]``; points are kept by their running
    index (every k-th), so a growing trail keeps the same points from one message to the next.
    """
    n = len(points)
    if n <= limit:
        return list(points)
    stride = -(-n // (limit - 1))  # ceil: at most limit - 1 regular points + the newest
    start = (-first_index) % stride
    kept = [points[i] for i in range(start, n - 1, stride)]
    kept.append(points[n - 1])
    return kept


class StateMessages:
    """
    The state messages of a tick, built once and refilled in place.

    Fewer allocations per tick in the pacing thread; rclpy copies a message when it is
    published.
    """

    def __init__(self) -> None:
        self.pose = PoseStamped()
        self.odom = Odometry()
        self.spin_axis = Vector3Stamped()
        self.aero_angles = Vector3Stamped()
        self.aero_angles_linear = Vector3Stamped()
        self.aero_angles_quasi_steady = Vector3Stamped()

    def fill(
        self,
        sample: BallSample,
        stamp: Time,
        frame_id: str,
        child_frame_id: str,
        at_rest: bool = False,
    ) -> None:
        """
        Set every field from ``sample`` (one stamp shared by every message).

        pose and odom pose in ``frame_id``; odom twist in the body frame, zero when ``at_rest``
        (the landed state held after the landing: the ball lies on the ground); spin axis in
        ``frame_id``; aero angles (alpha, beta, delta) [rad] with the empty frame id, the
        linear theory's (frozen and quasi-steady) delta = acos(cos alpha cos beta).
        """
        px, py, pz = sample.position.tolist()
        qx, qy, qz, qw = q = sample.orientation.tolist()
        for msg, pose in ((self.pose, self.pose.pose), (self.odom, self.odom.pose.pose)):
            msg.header.stamp = stamp
            msg.header.frame_id = frame_id
            pose.position.x, pose.position.y, pose.position.z = px, py, pz
            o = pose.orientation
            o.x, o.y, o.z, o.w = qx, qy, qz, qw
        self.odom.child_frame_id = child_frame_id
        twist = self.odom.twist.twist
        if at_rest:
            vx = vy = vz = wx = wy = wz = 0.0
        else:
            vx, vy, vz = to_body_frame(q, sample.velocity.tolist())
            wx, wy, wz = to_body_frame(q, sample.angular_velocity.tolist())
        twist.linear.x, twist.linear.y, twist.linear.z = vx, vy, vz
        twist.angular.x, twist.angular.y, twist.angular.z = wx, wy, wz
        _fill_vector(self.spin_axis, stamp, frame_id, sample.axis.tolist())
        _fill_vector(self.aero_angles, stamp, ANGLES_FRAME, sample.aero_angles.tolist())
        for msg, angles in (
            (self.aero_angles_linear, sample.aero_angles_linear),
            (self.aero_angles_quasi_steady, sample.aero_angles_quasi_steady),
        ):
            alpha, beta = angles.tolist()
            delta = math.acos(max(-1.0, min(1.0, math.cos(alpha) * math.cos(beta))))
            _fill_vector(msg, stamp, ANGLES_FRAME, (alpha, beta, delta))


def _fill_vector(msg: Vector3Stamped, stamp: Time, frame_id: str, v: Sequence[float]) -> None:
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.vector.x, msg.vector.y, msg.vector.z = v


def vector_of(msg_vector) -> np.ndarray:
    """Numpy (3,) from a geometry_msgs Vector3/Point."""
    return np.array([msg_vector.x, msg_vector.y, msg_vector.z])


def to_plain(msg):
    """Return a message as plain data (dicts, lists, numbers, strings), to print as YAML/JSON."""
    if hasattr(msg, 'get_fields_and_field_types'):
        return {name: to_plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if isinstance(msg, (bytes, bytearray)):
        return list(msg) if len(msg) != 1 else msg[0]
    if hasattr(msg, 'tolist'):  # numpy arrays and scalars, array.array
        return msg.tolist()
    if isinstance(msg, (list, tuple)):
        return [to_plain(v) for v in msg]
    return msg


_CDR_HEADER = b'\x00\x01\x00\x00'  # encapsulation: plain CDR, little endian
_STAMP = struct.Struct('<iI')
_COUNT = struct.Struct('<I')
_POSE = struct.Struct('<7d')
_TWIST = struct.Struct('<6d')
_COVARIANCE = bytes(8 * 36)  # 36 zero doubles (exact model)


def _cdr_string(text: str, offset: int) -> tuple[bytes, int]:
    """CDR string at ``offset``: padding to 4, uint32 length with the NUL, UTF-8, NUL."""
    data = text.encode()
    out = bytes(-offset % 4) + _COUNT.pack(len(data) + 1) + data + b'\0'
    return out, offset + len(out)


def _frames_part(names: tuple[str, ...], offset: int) -> bytes:
    """Encode the frame strings from ``offset`` on, then pad to the doubles that follow."""
    out = b''
    for name in names:
        part, offset = _cdr_string(name, offset)
        out += part
    return out + bytes(-offset % 8)


class EntityMessages:
    """
    A spawned entity's PoseStamped, Odometry and TransformStamped as serialized bytes.

    Encoded by hand in the CDR that rclpy's ``serialize_message`` writes (bit for bit, tested),
    with the frame strings and their padding encoded once: a publisher sends them as they
    are (about half the cost of publishing the message objects), and /tf gets one TFMessage
    of :meth:`tf_message`. pose and odom pose in ``frame_id``, odom twist in the body frame
    ``child_frame_id``, the transform ``frame_id`` -> ``child_frame_id``.
    """

    def __init__(self, frame_id: str, child_frame_id: str) -> None:
        self.tf_ns = -1  # stamp of the last transform its user sent [ns] (tf2: no repeats)
        self.frames(frame_id, child_frame_id)

    def frames(self, frame_id: str, child_frame_id: str) -> None:
        """Set the frame ids (the parameters may change them); ``frame_ids`` holds them."""
        self.frame_ids = (frame_id, child_frame_id)
        self._pose_frames = _frames_part((frame_id,), 8)  # after the stamp
        self._odom_frames = _frames_part((frame_id, child_frame_id), 8)
        # A transform of a TFMessage starts 4-aligned: at 4 mod 8 (the first) or 0 mod 8.
        self._tf_frames = {
            start: _frames_part((frame_id, child_frame_id), start + 8) for start in (0, 4)
        }

    def pose(self, stamp: Time, position, orientation) -> bytes:
        """geometry_msgs/PoseStamped: position [m], orientation (x, y, z, w) in frame_id."""
        return b''.join(
            (
                _CDR_HEADER,
                _STAMP.pack(stamp.sec, stamp.nanosec),
                self._pose_frames,
                _POSE.pack(*position, *orientation),
            )
        )

    def odom(self, stamp: Time, position, orientation, velocity, angular_velocity) -> bytes:
        """nav_msgs/Odometry: the pose, the world-frame velocities [m/s, rad/s] in body axes."""
        return b''.join(
            (
                _CDR_HEADER,
                _STAMP.pack(stamp.sec, stamp.nanosec),
                self._odom_frames,
                _POSE.pack(*position, *orientation),
                _COVARIANCE,
                _TWIST.pack(
                    *to_body_frame(orientation, velocity),
                    *to_body_frame(orientation, angular_velocity),
                ),
                _COVARIANCE,
            )
        )

    def transform(self, offset: int, stamp: Time, position, orientation) -> bytes:
        """Encode the TransformStamped element of a TFMessage that starts at CDR ``offset``."""
        return b''.join(
            (
                _STAMP.pack(stamp.sec, stamp.nanosec),
                self._tf_frames[offset % 8],
                _POSE.pack(*position, *orientation),
            )
        )


def tf_message_bytes(items) -> bytes:
    """tf2_msgs/TFMessage of (EntityMessages, stamp, position, orientation) items, serialized."""
    parts = [_CDR_HEADER, _COUNT.pack(len(items))]
    offset = 4
    for msgs, stamp, position, orientation in items:
        part = msgs.transform(offset, stamp, position, orientation)
        parts.append(part)
        offset += len(part)
    return b''.join(parts)


class TransformBatch:
    """
    tf2_msgs/TFMessage of many balls in one pass: the CDR laid out once, the numbers by numpy.

    :meth:`encode` takes the children's frame names only when the set of children changes
    (``key``); otherwise it copies the laid-out bytes and writes every stamp and pose with two
    array assignments (no Python work per ball). Bit for bit what rclpy serializes (tested).
    """

    def __init__(self) -> None:
        self._key = None
        self._template = b''
        self._stamp_at = np.empty(0, dtype=np.int64)  # index of each sec in the int32 view
        self._pose_at = np.empty(0, dtype=np.int64)  # index of each pose in the float64 view

    def encode(self, key, children, frame_id: str, stamp: Time, poses: np.ndarray) -> bytes:
        """
        Serialize transforms ``frame_id`` -> each child at one ``stamp``.

        ``children``: a function returning the child frame names (called when ``key``, any
        hashable naming the set, differs from the last call's); ``poses`` (N, 7): x, y, z [m],
        qx, qy, qz, qw per child, in their order.
        """
        if self._key != (key, frame_id):
            self._layout(children(), frame_id)
            self._key = (key, frame_id)
        buf = bytearray(self._template)
        if len(self._pose_at):
            words = np.frombuffer(buf, dtype='<i4', offset=4, count=(len(buf) - 4) // 4)
            words[self._stamp_at] = stamp.sec
            words[self._stamp_at + 1] = stamp.nanosec
            doubles = np.frombuffer(buf, dtype='<f8', offset=4, count=(len(buf) - 4) // 8)
            doubles[self._pose_at[:, None] + np.arange(7)] = poses
        return bytes(buf)

    def _layout(self, children: list[str], frame_id: str) -> None:
        parts, stamps, poses = [_CDR_HEADER, _COUNT.pack(len(children))], [], []
        offset = 4  # CDR offset (after the encapsulation header) of the first transform
        for child in children:
            frames = _frames_part((frame_id, child), offset + 8)
            stamps.append(offset // 4)
            poses.append((offset + 8 + len(frames)) // 8)
            parts += [bytes(8), frames, bytes(56)]
            offset += 64 + len(frames)
        self._template = b''.join(parts)
        self._stamp_at = np.array(stamps, dtype=np.int64)
        self._pose_at = np.array(poses, dtype=np.int64)
