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
Every topic the package's nodes publish or subscribe: name -> (message type, QoS profile).

Names and profiles are defined in :mod:`.qos`; this is the one table that pairs them with their
message types (the recorder records, ``echo`` prints and the tests subscribe from it). Topics
made at run time (a spawned entity's ``football/<entity>/pose`` and ``.../odom``, the tracker's
``football/track_<n>/...``, a rig camera's ``football/camera/<name>/...``) are :data:`PATTERNS`
of the same table; :func:`lookup` finds either. Each topic's page in msg_docs/ says what it
carries.
"""

from __future__ import annotations

from dataclasses import dataclass
import re

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    Vector3Stamped,
)
from nav_msgs.msg import Odometry, Path
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from . import qos
from .messages import Detection2DArray, TFMessage

STATE_TOPICS: dict[str, type] = {
    qos.POSE: PoseStamped,
    qos.ODOM: Odometry,
    qos.SPIN_AXIS: Vector3Stamped,
    qos.AERO_ANGLES: Vector3Stamped,
    qos.AERO_ANGLES_LINEAR: Vector3Stamped,
    qos.AERO_ANGLES_QUASI_STEADY: Vector3Stamped,
}
"""The simulator's state of the ball, one message each per tick (QoS ``qos.STATE``)."""

TOPICS: dict[str, tuple[type, QoSProfile]] = {
    **{topic: (cls, qos.STATE) for topic, cls in STATE_TOPICS.items()},
    qos.MARKERS: (MarkerArray, qos.MARKERS_QOS),
    qos.DIAGNOSTICS: (DiagnosticArray, qos.DIAGNOSTICS_QOS),
    qos.CLOCK: (Clock, qos.CLOCK_QOS),
    qos.RELEASE_REQUEST: (String, qos.REQUEST),
    qos.RELEASE_RESPONSE: (DiagnosticStatus, qos.REQUEST),
    qos.RELEASE_STATE: (Odometry, qos.REQUEST),
    qos.FLIGHT_ORDER: (String, qos.ORDER),
    qos.FLIGHT_ACK: (DiagnosticStatus, qos.ORDER),
    qos.OBSERVATION: (PointStamped, qos.STATE),
    qos.OBSERVATION_COV: (PoseWithCovarianceStamped, qos.STATE),
    qos.ESTIMATE: (Odometry, qos.STATE),
    qos.LANDING: (PoseWithCovarianceStamped, qos.STATE),
    qos.CATCH: (PoseWithCovarianceStamped, qos.STATE),
    qos.RECEIVER: (PoseWithCovarianceStamped, qos.STATE),
    qos.PREDICTED_PATH: (Path, qos.STATE),
    qos.PLAN_REQUEST: (String, qos.REQUEST),
    qos.PLAN_RESPONSE: (DiagnosticStatus, qos.REQUEST),
    qos.PLAN_PATH: (Path, qos.PLAN_PATH_QOS),
    **({qos.TF: (TFMessage, qos.TF_QOS)} if TFMessage is not None else {}),
    **({qos.TF_STATIC: (TFMessage, qos.TF_STATIC_QOS)} if TFMessage is not None else {}),
}


CAMERA_TOPICS: dict[str, type] = (
    {'camera_info': CameraInfo, 'detections': Detection2DArray}
    if Detection2DArray is not None else {}
)
"""Leaf of football/camera/<name>/<leaf> -> message type (QoS ``qos.STATE``)."""
ENTITY_TOPICS: dict[str, type] = {'pose': PoseStamped, 'odom': Odometry}
"""Leaf -> type of each spawned entity's state topics (:func:`qos.entity_topic`, ``qos.STATE``)."""
TRACK_TOPICS = (qos.ESTIMATE, qos.LANDING, qos.PREDICTED_PATH, qos.CATCH, qos.RECEIVER)
"""The tracker's topics that also exist per track (:func:`qos.track_topic`)."""
_TOKEN = '[A-Za-z][A-Za-z0-9_]*'  # one token of a ROS name


@dataclass(frozen=True)
class TopicPattern:
    """A family of topics made at run time: ``template`` for people, ``regex`` for names."""

    template: str
    regex: re.Pattern
    msg_type: type
    profile: QoSProfile


def _pattern(name: str, marker: str, shown: str, regex: str, cls, profile) -> TopicPattern:
    """Pattern of ``name`` whose ``marker`` stands for ``shown`` (template) and ``regex``."""
    before, after = name.split(marker)
    return TopicPattern(
        name.replace(marker, shown), re.compile(re.escape(before) + regex + re.escape(after)),
        cls, profile,
    )


PATTERNS: tuple[TopicPattern, ...] = (
    *(
        _pattern(qos.entity_topic('ENTITY', leaf), 'ENTITY', '<entity>', _TOKEN, cls, qos.STATE)
        for leaf, cls in ENTITY_TOPICS.items()
    ),
    *(
        _pattern(qos.track_topic(0, t), 'track_0', 'track_<n>', 'track_[0-9]{1,9}', *TOPICS[t])
        for t in TRACK_TOPICS
    ),
    *(
        _pattern(qos.camera_topic('CAMERA', leaf), 'CAMERA', '<name>', _TOKEN, cls, qos.STATE)
        for leaf, cls in CAMERA_TOPICS.items()
    ),
)
"""Topics made at run time, as patterns of relative names."""


def lookup(name: str) -> tuple[type, QoSProfile] | None:
    """Return (type, QoS) of a package topic by name (as in TOPICS, or a pattern's), else None."""
    if name in TOPICS:
        return TOPICS[name]
    for pattern in PATTERNS:
        if pattern.regex.fullmatch(name):
            return pattern.msg_type, pattern.profile
    return None


def known_names() -> list[str]:
    """Every topic name and pattern template, for error messages and ``--help``."""
    return list(TOPICS) + [p.template for p in PATTERNS]


def type_name(cls: type) -> str:
    """'geometry_msgs/msg/PoseStamped' for a generated message class."""
    module = cls.__module__.split('.')
    return f'{module[0]}/{module[1]}/{cls.__name__}'
