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
the body frame (``football``). All vectors are SI (m, m/s, rad, rad/s).
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, PoseStamped, Quaternion, Vector3, Vector3Stamped
from nav_msgs.msg import Odometry
import numpy as np
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from ..physics.flight import BallSample

try:  # the real tf2_msgs on a Jazzy install; pip_ros/tf2_msgs built by setup.sh on the pip ROS
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
except ImportError:  # pragma: no cover - no TF without tf2_msgs
    TFMessage = None

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


def _point(v: Sequence[float]) -> Point:
    return Point(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _vector(v: Sequence[float]) -> Vector3:
    return Vector3(x=float(v[0]), y=float(v[1]), z=float(v[2]))


def _quaternion(q: Sequence[float]) -> Quaternion:
    return Quaternion(x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def pose_stamped(sample: BallSample, stamp: Time, frame_id: str) -> PoseStamped:
    """Position + orientation (body x = spin axis, spin angle included) in ``frame_id``."""
    msg = PoseStamped(header=header(stamp, frame_id))
    msg.pose.position = _point(sample.position)
    msg.pose.orientation = _quaternion(sample.orientation)
    return msg


def odometry(sample: BallSample, stamp: Time, frame_id: str, child_frame_id: str) -> Odometry:
    """
    Pose in ``frame_id``.

    Twist (linear and angular velocity) in the body frame ``child_frame_id``, as
    nav_msgs/Odometry specifies. Covariances are zero (exact model).
    """
    msg = Odometry(header=header(stamp, frame_id), child_frame_id=child_frame_id)
    msg.pose.pose.position = _point(sample.position)
    msg.pose.pose.orientation = _quaternion(sample.orientation)
    msg.twist.twist.linear = _vector(to_body_frame(sample.orientation, sample.velocity))
    msg.twist.twist.angular = _vector(to_body_frame(sample.orientation, sample.angular_velocity))
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
    transform.transform.translation = _vector(sample.position)
    transform.transform.rotation = _quaternion(sample.orientation)
    return TFMessage(transforms=[transform])


def vector3_stamped(vec: Sequence[float], stamp: Time, frame_id: str) -> Vector3Stamped:
    return Vector3Stamped(header=header(stamp, frame_id), vector=_vector(vec))


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
    trail: Iterable[Sequence[float]],
    stamp: Time,
    frame_id: str,
    ball_length: float,
    ball_diameter: float,
    namespace: str = 'football',
) -> MarkerArray:
    """
    Build the RViz markers.

    Ball (ellipsoid), spin-axis arrow (red), velocity arrow (green, 0.1 s of flight long),
    trail (line strip of past positions).
    """
    hdr = header(stamp, frame_id)
    ball = Marker(header=hdr, ns=namespace, id=0, type=Marker.SPHERE, action=Marker.ADD)
    ball.pose.position = _point(sample.position)
    ball.pose.orientation = _quaternion(sample.orientation)
    ball.scale = _vector([ball_length, ball_diameter, ball_diameter])
    ball.color = _color(0.55, 0.27, 0.07)
    axis = Marker(header=hdr, ns=namespace, id=1, type=Marker.ARROW, action=Marker.ADD)
    axis.points = [_point(sample.position), _point(sample.position + 0.5 * sample.axis)]
    axis.scale = _vector([0.02, 0.04, 0.06])
    axis.color = _color(0.9, 0.1, 0.1)
    velocity = Marker(header=hdr, ns=namespace, id=2, type=Marker.ARROW, action=Marker.ADD)
    velocity.points = [_point(sample.position), _point(sample.position + 0.1 * sample.velocity)]
    velocity.scale = _vector([0.02, 0.04, 0.06])
    velocity.color = _color(0.1, 0.8, 0.1)
    path = Marker(header=hdr, ns=namespace, id=3, type=Marker.LINE_STRIP, action=Marker.ADD)
    path.points = [_point(p) for p in trail]
    path.scale = _vector([0.03, 0.0, 0.0])
    path.color = _color(0.2, 0.4, 1.0, 0.8)
    for marker in (axis, velocity, path):  # points are in the header frame: identity pose
        marker.pose.orientation.w = 1.0
    return MarkerArray(markers=[ball, axis, velocity, path])


def vector_of(msg_vector) -> np.ndarray:
    """Numpy (3,) from a geometry_msgs Vector3/Point."""
    return np.array([msg_vector.x, msg_vector.y, msg_vector.z])


def to_plain(msg):
    """Convert a message to plain data (dicts, lists, numbers, strings) for YAML/JSON."""
    if hasattr(msg, 'get_fields_and_field_types'):
        return {name: to_plain(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if isinstance(msg, (bytes, bytearray)):
        return list(msg) if len(msg) != 1 else msg[0]
    if hasattr(msg, 'tolist'):  # numpy arrays and scalars, array.array
        return msg.tolist()
    if isinstance(msg, (list, tuple)):
        return [to_plain(v) for v in msg]
    return msg
