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
A rosbag2 writer (rosbags) whose bags are what ``ros2 bag record`` (Jazzy) writes; no ROS needed.

Metadata version 9 with ``ros_distro: jazzy``; the first file named ``<folder>_0.mcap`` (or
``_0.db3``); mcap channels with ``offered_qos_profiles`` and ``topic_type_hash``; message
definitions as rosbag2_cpp's LocalMessageDefinitionSource stores them (:func:`msgdef`: the .msg
files as written, comments and defaults kept, each dependency once, in its order). The writer
can also close cleanly after a write error (:meth:`BagWriter.close_after_error`): chunks are
flushed outside ``Writer.write`` and a failed flush is cut back to the last complete record.

It extends rosbags' storage writers (their ``bio``, ``chunk``, ``channels`` and
``channel_stats`` attributes): setup.py pins the rosbags versions this is tested with.
"""

from __future__ import annotations

from collections import defaultdict
from io import BytesIO
import os
from pathlib import Path
import re
import sqlite3
import struct
import sys
import time

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.storage_mcap import (
    Channel,
    McapWriter,
    PendingChunk,
    write_channel,
    write_string,
)
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer

BAG_VERSION = 9  # rosbag2 metadata version written by Jazzy
ROS_DISTRO = 'jazzy'
SQLITE_COMMIT_S = 0.2  # sqlite3: commit at most this often (a write error loses at most this)
DELIMITER = '=' * 80
_FIELD_TYPE = re.compile(r'(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+')
_PRIMITIVES = frozenset(
    'bool byte char float32 float64 int8 uint8 int16 uint16 int32 uint32 int64 uint64 '
    'string'.split()
)


def _share(package: str) -> Path:
    """
    Return the package's share folder: the ament index's, else ``<prefix>/share`` (pip ROS).

    The ament index of each AMENT_PREFIX_PATH entry is a marker file
    ``share/ament_index/resource_index/packages/<package>``.
    """
    for prefix in filter(None, os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)):
        marker = Path(prefix) / 'share' / 'ament_index' / 'resource_index' / 'packages' / package
        if marker.is_file():
            return Path(prefix) / 'share' / package
    return Path(sys.prefix) / 'share' / package


def _msg_file(type_name: str) -> tuple[str, str]:
    """(text, package) of ``pkg/Type`` or ``pkg/msg/Type`` (OSError if there is no file)."""
    parts = type_name.split('/')
    package, folder, name = (parts[0], 'msg', parts[1]) if len(parts) == 2 else parts
    return (_share(package) / folder / f'{name}.msg').read_text(), package


def _dependencies(text: str, package: str) -> list[str]:
    found = set()
    for match in _FIELD_TYPE.finditer(text):
        kind = match.group(1)
        if kind not in _PRIMITIVES:
            found.add(kind if '/' in kind else f'{package}/{kind}')
    return sorted(found)


def msgdef(type_name: str) -> str:
    """
    Return the complete ros2msg definition of ``type_name`` as ``ros2 bag record`` stores it.

    The type's .msg file, then each dependency not seen yet (sorted by name, depth first),
    preceded by a line of 80 '=' and ``MSG: pkg/Type``. Raises OSError when a .msg file is
    missing.
    """
    seen: set[str] = set()

    def full(name: str, depth: int) -> str:
        if depth <= 0:
            raise OSError(f'message definition of {type_name} nested too deeply')
        text, package = _msg_file(name)
        out = text
        for dep in _dependencies(text, package):
            if dep not in seen:
                seen.add(dep)
                out += f'\n{DELIMITER}\nMSG: {dep}\n' + full(dep, depth - 1)
        return out

    return full(type_name, 50)


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
        named = self.path.with_name(f'{path.name}_0.mcap')  # ros2 bag record's first file
        os.replace(self.path, named)
        self.path = named
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
        self.conn.close()  # rosbags names the file <folder>.db3; rosbag2 <folder>_0.db3
        named = self.path.with_name(f'{path.name}_0.db3')
        os.replace(self.path, named)
        self.path = named
        self.conn = sqlite3.connect(f'file:{self.path}', uri=True)
        self.cursor = self.conn.cursor()
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

    def add_ros_connection(self, topic: str, msgtype: str, typestore, offered_qos: list):
        """
        Add a topic with the definition ``ros2 bag record`` stores (:func:`msgdef`).

        The RIHS01 hash comes from ``typestore``, which also gives the definition of a type
        whose .msg files are not installed.
        """
        try:
            definition = msgdef(msgtype)
        except OSError:
            definition = typestore.generate_msgdef(msgtype, ros_version=2)[0]
        return self.add_connection(
            topic,
            msgtype,
            msgdef=definition,
            rihs01=typestore.hash_rihs01(msgtype),
            serialization_format='cdr',
            offered_qos_profiles=offered_qos,
        )

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
