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
Recorder node: the football_ros topics into a rosbag2 bag (mcap or sqlite3), with ``rosbags``.

Messages are taken serialized (CDR, no deserialisation) and written with their receive time
from the node's clock, as ``ros2 bag record`` does: wall time, or /clock time when the node
runs with ``use_sim_time:=true`` (messages that arrive before the first /clock are stamped 0).
Each topic's connection carries the message definition (Jazzy type store), its RIHS01 type
hash and the QoS profiles its publishers offer; metadata.yaml says ``ros_distro: jazzy`` and
mcap channels carry ``offered_qos_profiles`` and ``topic_type_hash``, as rosbag2 (jazzy) writes.

Ctrl-C or SIGTERM closes the bag properly (metadata.yaml written, last chunk flushed). A write
error (disk full, file size limit, I/O error) stops the recording: the bag is closed with what
was already on disk (readable, counts consistent), one ERROR line is logged, an ERROR status
goes to /diagnostics and the node exits with status 1. To have room for that close even on a
full disk, the recorder keeps an 8 MiB reserve file in the bag folder while recording.

``football-ros record --out DIR [--storage mcap|sqlite3] [--topics T ...]`` and
``ros2 run football_ros recorder --ros-args -p output:=DIR`` are the same node. Parameters
(read at start-up): ``output`` (bag folder; unset or "" = football_<date>_<time>), ``storage``
(mcap or sqlite3), ``topics`` (string array; unset, [] or [""] = every football_ros topic).
Every topic includes those made at run time (a spawned entity's ``football/<entity>/pose`` and
``.../odom``, the tracker's ``football/track_<n>/...``: ``topics.PATTERNS``), found in the
graph every ``DISCOVERY_S`` and recorded from then on, :data:`MAX_DISCOVERED` at most; such a
topic can also be named in ``topics``.
"""

from __future__ import annotations

import argparse
import datetime
import os
from pathlib import Path
import signal
import sqlite3
import sys
import threading
import time
from typing import Sequence

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2.errors import WriterError
from rosbags.typesys import get_typestore, Stores

from . import messages as mb
from . import qos
from .logs import throttled
from .params import declare_all, ParamSpec
from .runner import run_node
from .topics import known_names, lookup, PATTERNS, TOPICS, type_name
from ..bagfile import BAG_VERSION, BagWriter

NODE_NAME = 'football_recorder'
DIAGNOSTIC_NAME = 'football_ros: recorder'
RESERVE_NAME = '.football_ros_reserve'
RESERVE_BYTES = 8 << 20  # > one mcap chunk (1 MiB + one message) + summary + metadata.yaml
EXIT_WRITE_ERROR = 1
DRAIN_S = 3.0
"""After a stop signal, messages still queued are written for up to this long [s] (until the
topics have been quiet for 0.2 s): a bag stopped right after a flight holds the flight's tail."""
STORAGES = ('mcap', 'sqlite3')
DISCOVERY_S = 0.2
"""How often the graph is read for new topics of the run-time patterns [s]."""
MAX_DISCOVERED = 1024
"""Run-time topics (entities, tracks) recorded at most; more are named in a warning."""


def _bag_qos(profile: QoSProfile) -> Qos:
    def duration(d) -> QosTime:
        sec, nsec = divmod(int(d.nanoseconds), 1_000_000_000)
        return QosTime(sec=sec, nsec=nsec)

    return Qos(
        history=QosHistory(int(profile.history)),
        depth=int(profile.depth),
        reliability=QosReliability(int(profile.reliability)),
        durability=QosDurability(int(profile.durability)),
        deadline=duration(profile.deadline),
        lifespan=duration(profile.lifespan),
        liveliness=QosLiveliness(int(profile.liveliness)),
        liveliness_lease_duration=duration(profile.liveliness_lease_duration),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )


def default_bag_name() -> str:
    return datetime.datetime.now().strftime('football_%Y%m%d_%H%M%S')


PARAMETERS = (
    ParamSpec(
        'output',
        '',
        "Bag folder to create; unset or '' = football_<date>_<time>",
        read_only=True,
        optional=True,
    ),
    ParamSpec(
        'storage', 'mcap', 'Storage plugin', choices=STORAGES, read_only=True, optional=True
    ),
    ParamSpec(
        'topics',
        [''],
        "Topics to record; unset, [] or [''] = every topic the package publishes",
        read_only=True,
        optional=True,
    ),
)


class RecorderNode(Node):
    """Subscribes (serialized) to the football_ros topics and writes a rosbag2 bag."""

    PARAMETERS = PARAMETERS

    def __init__(
        self,
        output: str | None = None,
        storage: str | None = None,
        topics: Sequence[str] | None = None,
        registry: list | None = None,
    ) -> None:
        super().__init__(NODE_NAME)
        self._lock = threading.Lock()
        self._closed = True  # until the bag is open
        self.exit_code = 0
        declare_all(self, PARAMETERS)
        out = output or self.output or default_bag_name()
        store = storage or self.storage
        wanted = [t for t in (topics or self.topics) if t]
        selected = {}
        for name in wanted or list(TOPICS):
            try:
                full = self.resolve_topic_name(name)
            except Exception as exc:  # rclpy raises its own types for invalid names
                raise ValueError(f"parameter 'topics': invalid topic name '{name[:200]}'") from exc
            found = lookup(self._relative(full)) or TOPICS.get(full)  # absolute: /tf, /clock
            if found is None:
                raise ValueError(
                    f"parameter 'topics': unknown topic '{name[:200]}' "
                    f'(known: {", ".join(known_names())})'
                )
            selected[full] = found
        if '\0' in out or len(out) > 4096:
            raise ValueError("parameter 'output' must be a folder path (no NUL, < 4096 chars)")
        self.path = Path(out).resolve()
        if self.path.exists():
            raise ValueError(f"'{self.path}' exists already: rosbag2 needs a new folder")
        self._typestore = get_typestore(Stores.ROS2_JAZZY)
        plugin = StoragePlugin.MCAP if store == 'mcap' else StoragePlugin.SQLITE3
        self._writer = BagWriter(self.path, version=BAG_VERSION, storage_plugin=plugin)
        self._reserve = self.path / RESERVE_NAME
        if registry is not None:  # main() closes the bag even if a signal cuts start-up short
            registry.append(self)
        try:
            self._writer.open()
            self._closed = False
            _allocate(self._reserve, RESERVE_BYTES)
        except (OSError, sqlite3.Error) as exc:
            raise ValueError(f"cannot create the bag '{self.path}': {_reason(exc)}") from None
        self._connections: dict[str, object] = {}
        self.drain_s = DRAIN_S  # the runner writes what the readers hold after Ctrl-C
        self.last_activity = time.monotonic()
        self._diag_pub = self.create_publisher(
            DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS
        )
        self._subscribed: set[str] = set()
        for topic, (cls, profile) in selected.items():
            self._subscribe(topic, cls, profile)
        self._discovered = 0
        if not wanted:  # every topic: also those made at run time
            self.create_timer(DISCOVERY_S, self._discover)
        self.get_logger().info(f'ready: recording {len(selected)} topics to {self.path} ({store})')

    def _relative(self, full: str) -> str:
        """Return ``full`` relative to this node's namespace (as it is if outside it)."""
        prefix = self.get_namespace().rstrip('/') + '/'
        return full[len(prefix):] if full.startswith(prefix) else full

    def _subscribe(self, topic: str, cls, profile: QoSProfile) -> None:
        self._subscribed.add(topic)
        self.create_subscription(  # deep readers: a recorder short of CPU catches up
            cls,
            topic,
            lambda data, t=topic, c=cls, p=profile: self._write(t, c, p, data),
            qos.inbox(profile),
            raw=True,
        )

    def _discover(self) -> None:
        """Subscribe to the new topics of the run-time patterns that the graph shows."""
        for topic, types in self.get_topic_names_and_types():
            if topic in self._subscribed or not self._relative(topic).startswith('football/'):
                continue
            found = next(
                (p for p in PATTERNS if p.regex.fullmatch(self._relative(topic))), None
            )
            if found is None or type_name(found.msg_type) not in types:
                continue
            if self._discovered >= MAX_DISCOVERED:
                throttled(
                    self.get_logger(), 'warning',
                    f"not recording '{topic[:200]}' (and others): {MAX_DISCOVERED} run-time "
                    'topics are recorded already',
                    10.0,
                )
                return
            self._discovered += 1
            self._subscribe(topic, found.msg_type, found.profile)
            self.get_logger().info(f"recording '{topic}' (it appeared in the graph)")

    def _connection(self, topic: str, cls, profile: QoSProfile):
        offered = [info.qos_profile for info in self.get_publishers_info_by_topic(topic)]
        conn = self._writer.add_ros_connection(
            topic, type_name(cls), self._typestore, [_bag_qos(p) for p in offered or [profile]]
        )
        self._connections[topic] = conn
        self.get_logger().info(f"recording '{topic}' (first message received)")
        return conn

    def _write(self, topic: str, cls, profile: QoSProfile, data: bytes) -> None:
        self.last_activity = time.monotonic()
        stamp = self.get_clock().now().nanoseconds
        with self._lock:
            if self._closed:
                return
            try:
                conn = self._connections.get(topic) or self._connection(topic, cls, profile)
                self._writer.write(conn, stamp, data)
                self._writer.checkpoint()
            except (OSError, sqlite3.Error, WriterError) as exc:
                self._fail(exc)

    def _fail(self, exc: Exception) -> None:
        """Stop recording after a write error; keep what is on disk readable (lock held)."""
        self._closed = True
        _remove(self._reserve)  # room to finish the bag on a full disk
        lost, error = self._writer.close_after_error()
        if error is not None:
            kept = f'the bag could not be closed ({_reason(error)})'
        else:
            kept = 'the bag is closed and readable' + (
                f' ({lost} messages not yet on disk lost)' if lost else ''
            )
        total = sum(self._writer.counts.values())
        text = (
            f"write error on '{self.path}': {_reason(exc)}; recording stopped after "
            f'{total} messages, {kept}'
        )
        self.get_logger().error(text)
        self.exit_code = EXIT_WRITE_ERROR
        status = mb.diagnostic_status(
            DIAGNOSTIC_NAME,
            'ERROR',
            text,
            {'bag': str(self.path), 'messages': total, 'error': _reason(exc)},
            hardware_id=self.get_fully_qualified_name(),
        )
        self._diag_pub.publish(
            DiagnosticArray(header=mb.header(self.get_clock().now().to_msg(), ''), status=[status])
        )
        # Let DDS deliver the status (every matched reader acknowledges it, 3 s at most), then
        # end the node (main returns exit_code).
        self.create_timer(0.1, self._shut_down_after_failure)

    def _shut_down_after_failure(self) -> None:
        self._diag_pub.wait_for_all_acked(Duration(seconds=3.0))
        self.context.try_shutdown()

    def close(self) -> None:
        """Finish the bag (idempotent)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                self._writer.close()
            except (OSError, sqlite3.Error) as exc:
                self.get_logger().error(f"could not close '{self.path}': {_reason(exc)}")
                self.exit_code = EXIT_WRITE_ERROR
            _remove(self._reserve)
        counts = {c.topic: self._writer.counts[c.id] for c in self._writer.connections}
        summary = ', '.join(f'{t} {n}' for t, n in sorted(counts.items())) or 'no messages'
        print(
            f'[recorder] wrote {sum(counts.values())} messages to {self.path}: {summary}',
            file=sys.stderr,
            flush=True,
        )


def _allocate(path: Path, size: int) -> None:
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    try:
        try:
            os.posix_fallocate(fd, 0, size)
        except OSError as exc:
            if exc.errno not in (95,):  # EOPNOTSUPP: fall back to writing zeros
                raise
            os.write(fd, bytes(size))
    finally:
        os.close(fd)


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass


def _reason(exc: Exception) -> str:
    return getattr(exc, 'strerror', None) or str(exc) or type(exc).__name__


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ros_args = argv[argv.index('--ros-args'):] if '--ros-args' in argv else []
    own = argv[: len(argv) - len(ros_args)]
    parser = argparse.ArgumentParser(
        prog='football-ros record',
        description=__doc__.splitlines()[0].replace('``', ''),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog='parameters (--ros-args -p NAME:=VALUE; the options above win):\n'
        + '\n'.join(spec.help_line() for spec in PARAMETERS),
    )
    parser.add_argument('--out', help='bag folder to create (default: football_<date>_<time>)')
    parser.add_argument('--storage', choices=STORAGES, help='storage plugin (default mcap)')
    parser.add_argument(
        '--topics', nargs='+', help='topics to record (default: all football_ros topics)'
    )
    args = parser.parse_args(own)
    if hasattr(signal, 'SIGXFSZ'):  # a file size limit gives EFBIG (handled) instead of a kill
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    nodes: list[RecorderNode] = []
    code = run_node(
        lambda: RecorderNode(args.out, args.storage, args.topics, nodes), ros_args, 'recorder'
    )
    for node in nodes:  # a signal between start-up and spin skips the runner's close()
        node.close()
    return code or max((node.exit_code for node in nodes), default=0)


if __name__ == '__main__':
    raise SystemExit(main())
