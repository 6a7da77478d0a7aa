"""Recorder node: the football_ros topics into a rosbag2 bag (mcap or sqlite3), with ``rosbags``.

Messages are taken serialized (CDR, no deserialisation) and written with their receive time.
Each topic's connection carries the message definition (Jazzy type store) and the QoS profiles
its publishers offer. Ctrl-C or SIGTERM closes the bag properly (metadata.yaml written, last
chunk flushed). ``football-ros record --out DIR [--storage mcap|sqlite3] [--topics T ...]``
and ``ros2 run football_ros recorder --ros-args -p output:=DIR`` are the same node.
"""

from __future__ import annotations

import argparse
import datetime
import sys
import threading
from pathlib import Path
from typing import Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from . import qos
from .params import declare
from .runner import run_node

NODE_NAME = "football_recorder"
BAG_VERSION = 9  # rosbag2 metadata version written by Jazzy

# topic -> (message class, QoS to subscribe with; matches what the football_ros nodes offer)
TOPICS = {
    **{topic: (cls, qos.STATE) for topic, cls in (
        (qos.POSE, PoseStamped), (qos.ODOM, Odometry), (qos.SPIN_AXIS, Vector3Stamped),
        (qos.AERO_ANGLES, Vector3Stamped), (qos.AERO_ANGLES_LINEAR, Vector3Stamped))},
    qos.MARKERS: (MarkerArray, qos.MARKERS_QOS),
    qos.DIAGNOSTICS: (DiagnosticArray, qos.DIAGNOSTICS_QOS),
    qos.CLOCK: (Clock, qos.CLOCK_QOS),
    qos.RELEASE_REQUEST: (String, qos.REQUEST),
    qos.RELEASE_RESPONSE: (DiagnosticStatus, qos.REQUEST),
    qos.RELEASE_STATE: (Odometry, qos.REQUEST),
    qos.FLIGHT_ORDER: (String, qos.ORDER),
}


def type_name(cls) -> str:
    """'geometry_msgs/msg/PoseStamped' for a generated message class."""
    module = cls.__module__.split(".")
    return f"{module[0]}/msg/{cls.__name__}"


def _bag_qos(profile: QoSProfile) -> Qos:
    def duration(d) -> QosTime:
        sec, nsec = divmod(int(d.nanoseconds), 1_000_000_000)
        return QosTime(sec=sec, nsec=nsec)

    return Qos(history=QosHistory(int(profile.history)), depth=int(profile.depth),
               reliability=QosReliability(int(profile.reliability)),
               durability=QosDurability(int(profile.durability)),
               deadline=duration(profile.deadline), lifespan=duration(profile.lifespan),
               liveliness=QosLiveliness(int(profile.liveliness)),
               liveliness_lease_duration=duration(profile.liveliness_lease_duration),
               avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions))


def default_bag_name() -> str:
    return datetime.datetime.now().strftime("football_%Y%m%d_%H%M%S")


class RecorderNode(Node):
    """Subscribes (serialized) to the football_ros topics and writes a rosbag2 bag."""

    def __init__(self, output: str | None = None, storage: str | None = None,
                 topics: Sequence[str] | None = None) -> None:
        super().__init__(NODE_NAME)
        out = declare(self, "output", "", "Bag folder to create; empty = football_<date>_<time>")
        store = declare(self, "storage", "mcap", "Storage plugin: mcap or sqlite3")
        wanted = declare(self, "topics", [""], "Topics to record; empty = all football_ros topics")
        out = output or out or default_bag_name()
        store = storage or store
        wanted = [t for t in (topics or wanted) if t]
        if store not in ("mcap", "sqlite3"):
            raise ValueError(f"storage must be 'mcap' or 'sqlite3', got '{store}'")
        resolved = {self.resolve_topic_name(t): t for t in TOPICS}
        selected = {}
        for name in wanted or list(TOPICS):
            full = self.resolve_topic_name(name)
            if full not in resolved:
                raise ValueError(f"unknown topic '{name}' (known: {', '.join(sorted(resolved))})")
            selected[full] = TOPICS[resolved[full]]
        self.path = Path(out).resolve()
        if self.path.exists():
            raise ValueError(f"'{self.path}' exists already: rosbag2 needs a new folder")
        self._typestore = get_typestore(Stores.ROS2_JAZZY)
        plugin = StoragePlugin.MCAP if store == "mcap" else StoragePlugin.SQLITE3
        self._writer = Writer(self.path, version=BAG_VERSION, storage_plugin=plugin)
        self._writer.open()
        self._lock = threading.Lock()
        self._closed = False
        self._connections: dict[str, object] = {}
        self.counts: dict[str, int] = {}
        for topic, (cls, profile) in selected.items():
            self.create_subscription(cls, topic, lambda data, t=topic, c=cls, p=profile: self._write(t, c, p, data),
                                     profile, raw=True)
        self.get_logger().info(f"ready: recording {len(selected)} topics to {self.path} ({store})")

    def _connection(self, topic: str, cls, profile: QoSProfile):
        offered = [info.qos_profile for info in self.get_publishers_info_by_topic(topic)]
        conn = self._writer.add_connection(topic, type_name(cls), typestore=self._typestore,
                                           serialization_format="cdr",
                                           offered_qos_profiles=[_bag_qos(p) for p in offered or [profile]])
        self._connections[topic] = conn
        self.get_logger().info(f"recording '{topic}' (first message received)")
        return conn

    def _write(self, topic: str, cls, profile: QoSProfile, data: bytes) -> None:
        stamp = self.get_clock().now().nanoseconds
        with self._lock:
            if self._closed:
                return
            conn = self._connections.get(topic) or self._connection(topic, cls, profile)
            self._writer.write(conn, stamp, data)
            self.counts[topic] = self.counts.get(topic, 0) + 1

    def close(self) -> None:
        """Finish the bag (idempotent)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._writer.close()
        total = sum(self.counts.values())
        summary = ", ".join(f"{t} {n}" for t, n in sorted(self.counts.items())) or "no messages"
        print(f"[recorder] wrote {total} messages to {self.path}: {summary}", file=sys.stderr, flush=True)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ros_args = argv[argv.index("--ros-args"):] if "--ros-args" in argv else []
    own = argv[:len(argv) - len(ros_args)]
    parser = argparse.ArgumentParser(prog="football-ros record",
                                     description=__doc__.splitlines()[0].replace("``", ""))
    parser.add_argument("--out", help="bag folder to create (default: football_<date>_<time>)")
    parser.add_argument("--storage", choices=("mcap", "sqlite3"), help="storage plugin (default mcap)")
    parser.add_argument("--topics", nargs="+", help="topics to record (default: all football_ros topics)")
    args = parser.parse_args(own)
    return run_node(lambda: RecorderNode(args.out, args.storage, args.topics), ros_args, "recorder")


if __name__ == "__main__":
    raise SystemExit(main())
