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
Measured flights for ``football-ros fit``: a CSV of fixes, or a bag of a ball's positions.

A CSV has a header naming its columns, in any order: ``t,x,y,z`` (required: time [s] and
position [m] in ``field``), ``sx,sy,sz`` (optional: an observed spin axis, unit, either sign;
all three empty on a row where none was seen) and ``sigma`` (optional: that fix's noise, 1
sigma per axis [m]). Other columns are ignored, so that a ``football-ros simulate`` CSV is a
track too. One CSV is one flight. A bag (its folder, or its .mcap/.db3 file) holds fixes on
``football/observation`` (geometry_msgs/PointStamped, the camera's) or a ball's pose
(geometry_msgs/PoseStamped, whose body x is the axis, observed); its flights are split where the
stream pauses for more than ten median gaps. Every bad cell, row or message raises ValueError
naming the file and the row (the CSV's line, or the message's number on its topic).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..identification.track import MAX_FIXES, MIN_FIXES, Track
from ..physics import frames

MAX_CSV_BYTES = 256 << 20
"""Largest CSV read [bytes]."""
MAX_BAG_MESSAGES = 1_000_000
"""Most messages read from a bag's topic."""
REQUIRED = ('t', 'x', 'y', 'z')
AXIS = ('sx', 'sy', 'sz')
OBSERVATION_SUFFIX = 'football/observation'
POSE_TYPE = 'geometry_msgs/msg/PoseStamped'
POINT_TYPE = 'geometry_msgs/msg/PointStamped'


def read_tracks(path: str | Path, topic: str | None = None) -> tuple[list[Track], list[str]]:
    """
    Return the flights in ``path`` and warnings (bag segments too short to fit, skipped).

    ``topic`` picks a bag's topic (default: its one football/observation topic, else its one
    PoseStamped topic ending in 'pose').
    """
    path = Path(path)
    if path.is_dir() or path.suffix in ('.mcap', '.db3'):
        return read_bag(path, topic)
    if topic is not None:
        raise ValueError(f'{path}: --topic is for bags, not CSV files')
    return [read_csv(path)], []


def read_csv(path: Path) -> Track:
    """Read one flight from a CSV (the module docstring); ValueError naming file and line."""
    if not path.is_file():
        raise ValueError(f'{path}: no such file')
    if path.stat().st_size > MAX_CSV_BYTES:
        raise ValueError(f'{path}: larger than {MAX_CSV_BYTES >> 20} MiB')
    with open(path, newline='', encoding='utf-8', errors='replace') as handle:
        reader = csv.reader(handle)
        header = [h.strip() for h in next(reader, [])]
        missing = [c for c in REQUIRED if c not in header]
        if missing:
            raise ValueError(
                f'{path} line 1: the header lacks column(s) {", ".join(missing)} (needs '
                f't,x,y,z; optional sx,sy,sz and sigma), got {",".join(header)[:80]!r}'
            )
        if len(set(header)) != len(header):
            raise ValueError(f'{path} line 1: a column is named twice')
        has_axis = [c in header for c in AXIS]
        if any(has_axis) and not all(has_axis):
            raise ValueError(f'{path} line 1: the axis needs all three columns sx,sy,sz')
        index = {name: header.index(name) for name in header}
        wanted = list(REQUIRED) + (list(AXIS) if all(has_axis) else [])
        wanted += ['sigma'] if 'sigma' in index else []
        rows, lines = [], []
        for line, row in enumerate(reader, start=2):
            if not row or all(not cell.strip() for cell in row):
                continue
            if len(row) != len(header):
                raise ValueError(
                    f'{path} line {line}: {len(row)} cells, the header has {len(header)}'
                )
            if len(rows) >= MAX_FIXES:
                raise ValueError(f'{path} line {line}: more than {MAX_FIXES} fixes')
            rows.append([_cell(path, line, name, row[index[name]]) for name in wanted])
            lines.append(line)
    data = np.array(rows, dtype=float).reshape(-1, len(wanted))
    col = {name: i for i, name in enumerate(wanted)}
    axes = data[:, [col[c] for c in AXIS]] if all(has_axis) else None
    return Track(
        data[:, 0], data[:, 1:4], data[:, col['sigma']] if 'sigma' in col else None, axes,
        str(path), np.array(lines, dtype=int), 'line',
    )


def _cell(path: Path, line: int, name: str, text: str) -> float:
    """Return a cell as a finite float (an axis cell may be empty: not observed)."""
    text = text.strip()
    if not text and name in AXIS:
        return math.nan
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{path} line {line}: column '{name}' is not a number: "
                         f'{text[:30]!r}') from None
    if not math.isfinite(value):
        raise ValueError(f"{path} line {line}: column '{name}' is not finite: {text[:30]!r}")
    return value


def read_bag(path: Path, topic: str | None) -> tuple[list[Track], list[str]]:
    """Read the flights of a bag's fixes or poses (the module docstring)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import get_typestore, Stores

    folder = path.parent if path.is_file() else path
    if not (folder / 'metadata.yaml').exists():
        raise ValueError(f'{path}: not a rosbag2 folder (no metadata.yaml)')
    stamps, points, axes = [], [], []
    with AnyReader([folder], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conn = _pick(folder, reader.connections, topic)
        for count, (_, _, raw) in enumerate(reader.messages(connections=[conn]), start=1):
            if count > MAX_BAG_MESSAGES:
                raise ValueError(f'{folder}: more than {MAX_BAG_MESSAGES} messages on '
                                 f'{conn.topic}')
            msg = reader.deserialize(raw, conn.msgtype)
            stamps.append(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec)
            if conn.msgtype == POINT_TYPE:
                points.append((msg.point.x, msg.point.y, msg.point.z))
            else:
                p, q = msg.pose.position, msg.pose.orientation
                points.append((p.x, p.y, p.z))
                axes.append((q.x, q.y, q.z, q.w))
    if not stamps:
        raise ValueError(f'{folder}: no messages on {conn.topic}')
    stamps, points = np.array(stamps), np.array(points, dtype=float)
    order = np.argsort(stamps, kind='stable')  # recorded order may differ from capture order
    axis = None
    if axes:
        quats = np.array(axes, dtype=float)[order]
        norm = np.linalg.norm(quats, axis=1)
        good = np.isfinite(norm) & (norm > 1e-9)
        axis = np.full((len(order), 3), math.nan)
        axis[good] = frames.quaternion_to_matrix(quats[good] / norm[good, None])[:, :, 0]
        axis[~good] = math.inf  # refused by Track, naming the message
    tracks, warnings = [], []
    rows = order + 1
    for k, part in enumerate(_segments(stamps[order]), start=1):
        name = f'{folder} {conn.topic} flight {k}'  # rows: the messages' numbers on the topic
        if part.size < MIN_FIXES:
            warnings.append(f'{name}: {part.size} message(s), skipped (a flight needs '
                            f'{MIN_FIXES})')
            continue
        tracks.append(Track(stamps[order][part], points[order][part], None,
                            None if axis is None else axis[part], name, rows[part]))
    if not tracks:
        raise ValueError(f'{folder}: no flight of at least {MIN_FIXES} messages on {conn.topic}')
    return tracks, warnings


def _pick(folder: Path, connections, topic: str | None):
    """Return the connection to read: ``topic``, else the one observation, else the pose."""
    usable = [c for c in connections if c.msgtype in (POINT_TYPE, POSE_TYPE)]
    if topic is not None:
        chosen = [c for c in usable if c.topic == topic or c.topic.lstrip('/') == topic]
        if not chosen:
            raise ValueError(f'{folder}: no PointStamped or PoseStamped topic {topic!r} (has: '
                             f'{", ".join(sorted(c.topic for c in usable)) or "none"})')
        return chosen[0]
    for test in (lambda c: c.msgtype == POINT_TYPE and c.topic.endswith(OBSERVATION_SUFFIX),
                 lambda c: c.msgtype == POSE_TYPE and c.topic.endswith('pose')):
        found = [c for c in usable if test(c)]
        if len({c.topic for c in found}) > 1:
            raise ValueError(f'{folder}: several candidate topics '
                             f'({", ".join(sorted({c.topic for c in found}))}): pick one '
                             f'with --topic')
        if found:
            return found[0]
    raise ValueError(f'{folder}: no {OBSERVATION_SUFFIX} (PointStamped) or pose '
                     f'(PoseStamped) topic')


def _segments(stamps: np.ndarray) -> list[np.ndarray]:
    """Index runs of sorted ``stamps`` split where a gap exceeds ten median gaps."""
    index = np.arange(stamps.size)
    gaps = np.diff(stamps)
    positive = gaps[gaps > 0.0]
    if positive.size == 0:
        return [index]
    cuts = np.flatnonzero(gaps > 10.0 * np.median(positive)) + 1
    return np.split(index, cuts)
