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

"""QoS profiles and topic names: the one place for them (see msg_docs/ for each topic)."""

import copy

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

# Topic names, relative so that a namespace (--ros-args -r __ns:=/ball2) applies.
POSE = 'football/pose'
ODOM = 'football/odom'
SPIN_AXIS = 'football/spin_axis'
AERO_ANGLES = 'football/aero_angles'
AERO_ANGLES_LINEAR = 'football/aero_angles_linear'
AERO_ANGLES_QUASI_STEADY = 'football/aero_angles_quasi_steady'
MARKERS = 'football/markers'
DIAGNOSTICS = '/diagnostics'
CLOCK = '/clock'
TF = '/tf'  # absolute, as tf2_ros uses it: one TF tree per domain (see msg_docs/tf.md)
TF_STATIC = '/tf_static'  # static frames: the cameras' optical frames; fixes' frames (tracker)
CAMERA_LEAVES = ('camera_info', 'detections')  # a rig camera's topics (camera_topic)
RELEASE_REQUEST = 'football/release/request'
RELEASE_RESPONSE = 'football/release/response'
RELEASE_STATE = 'football/release/state'
FLIGHT_ORDER = 'football/flight/order'
FLIGHT_ACK = 'football/flight/ack'
RESET_SERVICE = 'football/reset'
PAUSE_SERVICE = 'football/pause'
OBSERVATION, ESTIMATE = 'football/observation', 'football/estimate'  # camera fixes, tracker
OBSERVATION_COV = 'football/observation_with_covariance'  # fixes with their covariance
# The simulator's simulation_interfaces services and action: private names (~/ = under the
# node's name), as ros_gz_sim names them under its server node.
GET_SIMULATOR_FEATURES = '~/get_simulator_features'
GET_SPAWNABLES = '~/get_spawnables'
SPAWN_ENTITY = '~/spawn_entity'
SPAWN_ENTITIES = '~/spawn_entities'
DELETE_ENTITY = '~/delete_entity'
GET_ENTITIES = '~/get_entities'
GET_ENTITY_INFO = '~/get_entity_info'
GET_ENTITY_BOUNDS = '~/get_entity_bounds'
GET_ENTITY_STATE = '~/get_entity_state'
GET_ENTITIES_STATES = '~/get_entities_states'
SET_ENTITY_STATE = '~/set_entity_state'
RESET_SIMULATION = '~/reset_simulation'
GET_SIMULATION_STATE = '~/get_simulation_state'
SET_SIMULATION_STATE = '~/set_simulation_state'
STEP_SIMULATION = '~/step_simulation'
SIMULATE_STEPS = '~/simulate_steps'

LANDING, PREDICTED_PATH = 'football/prediction/landing', 'football/prediction/path'  # tracker
PLAN_REQUEST, PLAN_RESPONSE = 'football/plan/request', 'football/plan/response'  # planner
PLAN_PATH = 'football/plan/path'
CATCH = 'football/prediction/catch'  # tracker: down through catch_height
RECEIVER = 'football/prediction/receiver'  # tracker: through the receiver's vertical plane


def track_topic(track_id: int, topic: str) -> str:
    """Per-track name of a tracker topic: 'football/estimate' -> 'football/track_3/estimate'."""
    return topic.replace('football/', f'football/track_{int(track_id)}/', 1)


# Ball state at up to 1-2 kHz: reliable so a recorder loses nothing; 1000 deep (1 s at 1 kHz)
# so a subscriber that stalls for a moment (GC, disk) catches up instead of losing samples.
STATE = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
# RViz markers and /diagnostics: reliable, shallow.
MARKERS_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
DIAGNOSTICS_QOS = MARKERS_QOS
# /tf_static as tf2_ros's StaticBroadcasterQoS / StaticListenerQoS: reliable, transient local
# (a late joiner gets every static transform), keep last 100.
TF_STATIC_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=100,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
PLAN_PATH_QOS = MARKERS_QOS  # planned paths: reliable, shallow
# /clock as rclcpp::ClockQoS: best effort, latest only.
CLOCK_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)
# /tf as tf2_ros's DynamicBroadcasterQoS / DynamicListenerQoS (reliable, volatile), but 1000
# deep like the state topics: a 1 s stall of a subscriber at 1 kHz loses no transform.
TF_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
# Requests and responses: reliable and deep, so a burst of requests is answered one by one.
REQUEST = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1000,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
# The package's own request writers (throw, the planner's throws, the demo): every request
# kept until the node's reader has acknowledged it. A KEEP_LAST writer overwrote requests that
# DDS still had to resend when the node's process fell behind a flood (bench/RESULTS.md,
# request benchmark); KEEP_ALL makes the writer wait instead (publish blocks, then raises).
REQUEST_WRITER = QoSProfile(
    history=HistoryPolicy.KEEP_ALL,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)
INBOX_DEPTH = 10000


def inbox(profile: QoSProfile) -> QoSProfile:
    """
    Return ``profile`` for a reader that must not lose what arrives while it lags.

    At least :data:`INBOX_DEPTH` deep (10 s of a 1000/s topic held in DDS while the node reads);
    a 1000-deep history dropped the oldest without a word when the reader lagged. Only for
    readers: deep writers slowed the matching of new endpoints.
    """
    deep = copy.copy(profile)
    deep.depth = max(profile.depth, INBOX_DEPTH)
    return deep


# The nodes' own request readers (release and planner): what their worker cannot take in time
# is answered 'busy'.
REQUEST_INBOX = inbox(REQUEST)
# Flight orders (release node -> simulator) and their acknowledgements (simulator -> release
# node): reliable, volatile (a simulator that is not there when a release is accepted must not
# fly it later), as deep as the requests so that a burst is not cut short in transit.
ORDER = REQUEST


# /tf_static as tf2_ros's StaticBroadcasterQoS: reliable, transient local (a late listener
# gets the transforms), one message holding every static transform.
TF_STATIC_QOS = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


def camera_topic(camera: str, leaf: str) -> str:
    """Topic of a rig camera: football/camera/<camera>/<leaf>, leaf one of CAMERA_LEAVES."""
    if leaf not in CAMERA_LEAVES:
        raise ValueError(f'a camera topic ends in one of {CAMERA_LEAVES}, got {leaf!r}')
    return f'football/camera/{camera}/{leaf}'


def entity_topic(entity: str, leaf: str) -> str:
    """State topic of a spawned entity: football/<entity>/<leaf> (leaf 'pose' or 'odom')."""
    return f'football/{entity}/{leaf}'


SERVICE_DEPTH = 1000
"""Requests a service (and the SimulateSteps action's goal, cancel and result services) keeps
waiting: rclpy's default of 10 drops a burst of callers beyond it without an answer."""


def service_qos() -> QoSProfile:
    """Services' QoS: as rclpy's services default (reliable, volatile), SERVICE_DEPTH deep."""
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=SERVICE_DEPTH,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
    )
