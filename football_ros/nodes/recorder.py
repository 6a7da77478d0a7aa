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
"""

from __future__ import annotations

import argparse
from collections import defaultdict
import datetime
from io import BytesIO
import os
from pathlib import Path
import signal
import sqlite3
import struct
import sys
import threading
import time
from typing import Sequence

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor
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
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.errors import WriterError
from rosbags.rosbag2.storage_mcap import (
    Channel,
    McapWriter,
    PendingChunk,
    write_channel,
    write_string,
)
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer
from rosbags.typesys import get_typestore, Stores
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from . import messages as mb
from . import qos
from .runner import run_node

try:  # tf2_msgs: the real package on a Jazzy install, a local build on the pip ROS (setup.sh)
    from tf2_msgs.msg import TFMessage
except ImportError:  # pragma: no cover - without tf2_msgs /tf is simply not recordable
    TFMessage = None

NODE_NAME = 'football_recorder'
DIAGNOSTIC_NAME = 'football_ros: recorder'
BAG_VERSION = 9  # rosbag2 metadata version written by Jazzy
ROS_DISTRO = 'jazzy'
RESERVE_NAME = '.football_ros_reserve'
RESERVE_BYTES = 8 << 20  # > one mcap chunk (1 MiB + one message) + summary + metadata.yaml
SQLITE_COMMIT_S = 0.2  # sqlite3: commit at most this often (a write error loses at most this)
EXIT_WRITE_ERROR = 1

# topic -> (message class, QoS to subscribe with; matches what the football_ros nodes offer)
TOPICS = {
    **{
        topic: (cls, qos.STATE)
        for topic, cls in (
            (qos.POSE, PoseStamped),
            (qos.ODOM, Odometry),
            (qos.SPIN_AXIS, Vector3Stamped),
            (qos.AERO_ANGLES, Vector3Stamped),
            (qos.AERO_ANGLES_LINEAR, Vector3Stamped),
            (qos.AERO_ANGLES_QUASI_STEADY, Vector3Stamped),
        )
    },
    qos.MARKERS: (MarkerArray, qos.MARKERS_QOS),
    qos.DIAGNOSTICS: (DiagnosticArray, qos.DIAGNOSTICS_QOS),
    qos.CLOCK: (Clock, qos.CLOCK_QOS),
    qos.RELEASE_REQUEST: (String, qos.REQUEST),
    qos.RELEASE_RESPONSE: (DiagnosticStatus, qos.REQUEST),
    qos.RELEASE_STATE: (Odometry, qos.REQUEST),
    qos.FLIGHT_ORDER: (String, qos.ORDER),
    **({qos.TF: (TFMessage, qos.TF_QOS)} if TFMessage is not None else {}),
}


def type_name(cls) -> str:
    """'geometry_msgs/msg/PoseStamped' for a generated message class."""
    module = cls.__module__.split('.')
    return f'{module[0]}/msg/{cls.__name__}'


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


def _jazzy(metadata: str) -> str:
    """Rosbags writes ``ros_distro: rosbags``; the bag is a Jazzy one."""
    return metadata.replace('ros_distro: rosbags', f'ros_distro: {ROS_DISTRO}')


class _File:
    """
    Unbuffered binary file that writes everything or raises (no silent short writes).

    So that after a write error the file can be cut back to its last complete record.
    """

    def __init__(self, path: Path, position: int) -> None:
        self._fd = os.open(path, os.O_WRONLY)
        self._pos = os.lseek(self._fd, position, os.SEEK_SET)

    def write(self, data) -> int:
        view = memoryview(data).cast('B')
        done = 0
        while done < len(view):
            done += os.write(self._fd, view[done:])
        self._pos += done
        return done

    def tell(self) -> int:
        return self._pos

    def truncate(self, size: int) -> None:
        os.ftruncate(self._fd, size)
        self._pos = os.lseek(self._fd, size, os.SEEK_SET)

    def flush(self) -> None:
        pass

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


class _Mcap(McapWriter):
    """
    rosbags' mcap writer with rosbag2 (jazzy) channel metadata and write-error recovery.

    Chunks are flushed by ``checkpoint()`` (outside ``Writer.write``, so the writer's counts
    always match the messages it holds); a failed flush cuts the file back to its last
    complete record and keeps the chunk in memory for ``close()`` or ``drop_pending()``.
    """

    def __init__(self, path: Path, compression) -> None:
        super().__init__(path, compression)
        self.bio.flush()
        position = self.bio.tell()
        self.bio.close()
        self.bio = _File(self.path, position)
        self._flush_due = False
        self._in_write = False

    def add_connection(self, connection, offered_qos_profiles: str) -> None:
        metadata = BytesIO()
        for key, value in (
            ('offered_qos_profiles', offered_qos_profiles),
            ('topic_type_hash', connection.digest),
        ):
            write_string(metadata, key)
            write_string(metadata, value)
        self.channels.append(
            Channel(
                connection.id,
                connection.msgtype,
                connection.topic,
                connection.ext.serialization_format,
                metadata.getvalue(),
            )
        )
        self.channel_stats[connection.id] = 0
        write_channel(self.chunk.bio, self.channels[-1], self.schemas)

    def write(self, connection, timestamp: int, data) -> None:
        self._in_write = True
        try:
            super().write(connection, timestamp, data)
        finally:
            self._in_write = False

    def close_chunk(self) -> None:
        if self._in_write:
            self._flush_due = True
            return
        start = self.bio.tell()
        try:
            super().close_chunk()
        except OSError:
            self.bio.truncate(start)
            raise
        self._flush_due = False

    def checkpoint(self) -> None:
        """Write the pending chunk to the file if it is full (raises OSError on failure)."""
        if self._flush_due:
            self.close_chunk()

    def drop_pending(self) -> dict[int, int]:
        """Forget the messages not yet on disk; returns their count per connection id."""
        dropped = {cid: len(msgs) for cid, msgs in self.chunk.msgs.items()}
        for cid, count in dropped.items():
            self.channel_stats[cid] -= count
        # Schema and channel records of the dropped chunk are in the summary written by close().
        self.chunk = PendingChunk(2**63 - 1, 0, BytesIO(), defaultdict(list))
        ends = [struct.unpack_from('<QQ', rec.getbuffer())[1] for rec in self.chunks]
        self.message_end_time = max(ends, default=0)
        if not ends:
            self.message_start_time = 2**63 - 1
        return dropped

    def close(self, version: int, metadata: str) -> None:
        if self.chunk.bio.tell():
            self.close_chunk()  # on its own: a failure cuts back only this chunk
        start = self.bio.tell()
        try:
            super().close(version, _jazzy(metadata))
        except OSError:
            self.bio.truncate(start)
            raise
        self.bio.close()


class _Sqlite3(Sqlite3Writer):
    """
    rosbags' sqlite3 writer that commits every SQLITE_COMMIT_S and says ``ros_distro: jazzy``.

    rosbags commits only at the end: a failure would roll the whole recording back.
    """

    SQLITE_SCHEMA = Sqlite3Writer.SQLITE_SCHEMA.replace("(4, 'rosbags')", f"(4, '{ROS_DISTRO}')")

    def __init__(self, path: Path, compression) -> None:
        super().__init__(path, compression)
        self._pending: dict[int, int] = defaultdict(int)
        self._last_commit = time.monotonic()

    def write(self, connection, timestamp: int, data) -> None:
        super().write(connection, timestamp, data)
        self._pending[connection.id] += 1

    def checkpoint(self) -> None:
        if time.monotonic() - self._last_commit >= SQLITE_COMMIT_S:
            self.conn.commit()
            self._pending.clear()
            self._last_commit = time.monotonic()

    def drop_pending(self) -> dict[int, int]:
        self.conn.rollback()
        dropped, self._pending = dict(self._pending), defaultdict(int)
        return dropped

    def close(self, version: int, metadata: str) -> None:
        super().close(version, _jazzy(metadata))


class BagWriter(Writer):
    """
    rosbags Writer whose bags match ``ros2 bag record`` (jazzy).

    They match in ros_distro, channel metadata and type hashes; the writer can close cleanly
    after a write error.
    """

    STORAGE_PLUGINS = {StoragePlugin.MCAP: _Mcap, StoragePlugin.SQLITE3: _Sqlite3}

    def checkpoint(self) -> None:
        self.storage.checkpoint()

    def drop_pending(self) -> int:
        """Forget the messages that are not on disk yet; returns how many."""
        dropped = self.storage.drop_pending()
        for cid, count in dropped.items():
            self.counts[cid] -= count
        return sum(dropped.values())

    def close_after_error(self) -> tuple[int, Exception | None]:
        """
        Close after a write error with what can be kept.

        The pending messages too if there is room, else only what is on disk. Returns
        (messages lost, error if not closed).
        """
        lost = 0
        try:
            if isinstance(self.storage, _Sqlite3):  # sqlite may have rolled back more
                lost = self.drop_pending()
            self.close()
            return lost, None
        except (OSError, sqlite3.Error):
            pass
        if self.storage is None:  # the storage is closed; metadata.yaml could not be written
            return lost, OSError('metadata.yaml could not be written')
        try:
            lost += self.drop_pending()
            self.close()
            return lost, None
        except (OSError, sqlite3.Error) as exc:
            return lost, exc

    def close(self) -> None:
        super().close()
        text = self.metapath.read_text('utf8')
        tmp = self.metapath.with_suffix('.yaml.tmp')
        tmp.write_text(_jazzy(text), 'utf8')
        tmp.replace(self.metapath)


def _string_param(node: Node, name: str, default: str, description: str) -> str:
    """Declare a read-only string parameter; unset (null in a params file) means ``default``."""
    value = node.declare_parameter(
        name,
        None,
        ParameterDescriptor(description=description, read_only=True, dynamic_typing=True),
    ).value
    if value is None:
        return default
    if not isinstance(value, str):
        raise ValueError(f"parameter '{name}' must be a string, got {value!r}")
    return value


def _topics_param(node: Node) -> list[str]:
    """``topics``: a string array; unset, [] (which rcl reads as unset) or [""] = all."""
    value = node.declare_parameter(
        'topics',
        None,
        ParameterDescriptor(
            description="Topics to record; unset, [] or [''] = every football_ros topic",
            read_only=True,
            dynamic_typing=True,
        ),
    ).value
    if value is None:
        return []
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(t, str) for t in value):
        raise ValueError(f"parameter 'topics' must be a list of topic names, got {value!r}")
    return [t for t in value if t]


class RecorderNode(Node):
    """Subscribes (serialized) to the football_ros topics and writes a rosbag2 bag."""

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
        out = _string_param(
            self, 'output', '', "Bag folder to create; '' = football_<date>_<time>"
        )
        store = _string_param(self, 'storage', 'mcap', 'Storage plugin: mcap or sqlite3')
        wanted = _topics_param(self)
        out = output or out or default_bag_name()
        store = storage or store
        wanted = [t for t in (topics or wanted) if t]
        if store not in ('mcap', 'sqlite3'):
            raise ValueError(f"parameter 'storage' must be 'mcap' or 'sqlite3', got '{store}'")
        resolved = {self.resolve_topic_name(t): t for t in TOPICS}
        selected = {}
        for name in wanted or list(TOPICS):
            try:
                full = self.resolve_topic_name(name)
            except Exception as exc:  # rclpy raises its own types for invalid names
                raise ValueError(f"parameter 'topics': invalid topic name '{name[:200]}'") from exc
            if full not in resolved:
                raise ValueError(
                    f"parameter 'topics': unknown topic '{name[:200]}' "
                    f'(known: {", ".join(sorted(resolved))})'
                )
            selected[full] = TOPICS[resolved[full]]
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
        self._diag_pub = self.create_publisher(
            DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS
        )
        for topic, (cls, profile) in selected.items():
            self.create_subscription(
                cls,
                topic,
                lambda data, t=topic, c=cls, p=profile: self._write(t, c, p, data),
                profile,
                raw=True,
            )
        self.get_logger().info(f'ready: recording {len(selected)} topics to {self.path} ({store})')

    def _connection(self, topic: str, cls, profile: QoSProfile):
        offered = [info.qos_profile for info in self.get_publishers_info_by_topic(topic)]
        conn = self._writer.add_connection(
            topic,
            type_name(cls),
            typestore=self._typestore,
            serialization_format='cdr',
            offered_qos_profiles=[_bag_qos(p) for p in offered or [profile]],
        )
        self._connections[topic] = conn
        self.get_logger().info(f"recording '{topic}' (first message received)")
        return conn

    def _write(self, topic: str, cls, profile: QoSProfile, data: bytes) -> None:
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
        prog='football-ros record', description=__doc__.splitlines()[0].replace('``', '')
    )
    parser.add_argument('--out', help='bag folder to create (default: football_<date>_<time>)')
    parser.add_argument(
        '--storage', choices=('mcap', 'sqlite3'), help='storage plugin (default mcap)'
    )
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
