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
Load a flight from a recorded bag (rosbags) or a ``football-ros simulate`` CSV, no ROS needed.

Both give a :class:`FlightRecord` of arrays in ``field``, SI units, t = 0 at the release, and,
when the source says so, what the flight is: the release (ball with its overrides, spin, model,
moment, aero settings). A CSV says it in its sidecar ``<name>.csv.json`` (written by
``simulate``, :func:`write_sidecar`); a bag in its ``football/flight/order`` messages (the
JSON of :meth:`football_ros.requests.FlightOrder.to_json`; the order of the flight taken).
A bag may hold several flights: the last one is taken. Flights follow each other in the bag's
order: a flight begins with its order message (``football/flight/order``, by receive time; its
first samples may arrive just before it, and those stamped from its release on are taken), or,
in a bag without orders, after the held landed state of the flight before. The landed state the
simulator republishes after the landing is dropped. A pause in the state stream (a stalled
simulator skips ticks) splits nothing: a sample's flight time is its stamp less the release's
stamp, and that is found from the flight itself (:func:`release_stamp`), so that a flight whose
first ticks were skipped still starts at its true time.
"""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass
import json
from pathlib import Path
from typing import Any

import numpy as np

from ..physics import frames
from ..physics.aero import AeroModel, resolve
from ..physics.flight import CSV_BASE_HEADER, CSV_HEADER, DEFAULT_STEP, Flight
from ..physics.presets import BallPreset
from ..physics.release import Release, RPM

SIDECAR_FORMAT = 'football_ros.simulate.sidecar'
SIDECAR_VERSION = 1
MAX_SIDECAR_BYTES = 1 << 20


@dataclass(frozen=True)
class FlightInfo:
    """
    What a flight file holds.

    The ball as flown (overrides and the full model's density applied), its preset name, spin
    at release [rad/s], model, moment curve, aero settings (None for the paper model) and where
    this was read from.
    """

    ball: BallPreset
    ball_name: str
    spin: float
    model: str
    moment: str
    aero: AeroModel | None
    origin: str

    @property
    def wind(self) -> np.ndarray:
        """Wind [m/s] in ``field`` (zeros without)."""
        return np.zeros(3) if self.aero is None else np.array(self.aero.wind, dtype=float)


@dataclass(frozen=True)
class FlightRecord:
    """
    t (N,) [s], position, velocity, axis (N, 3), alpha, beta, alpha_linear, beta_linear (N,) [rad].

    Spin (N,) [rad/s] about the axis when known, else None; alpha/beta_quasi_steady (N,) [rad]
    when the source has them, else None; info: what the flight is, or None.
    """

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    axis: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    alpha_linear: np.ndarray
    beta_linear: np.ndarray
    spin: np.ndarray | None
    source: str
    alpha_quasi_steady: np.ndarray | None = None
    beta_quasi_steady: np.ndarray | None = None
    info: FlightInfo | None = None


def sidecar_path(csv_path: str | Path) -> Path:
    """``<name>.csv.json`` beside a simulate CSV."""
    csv_path = Path(csv_path)
    return csv_path.with_name(csv_path.name + '.json')


def write_sidecar(
    csv_path: str | Path,
    release: Release,
    ball: BallPreset,
    aero: AeroModel | None,
    extra: dict[str, Any] | None = None,
) -> Path:
    """
    Write the sidecar of a simulate CSV.

    The release (ball name, overrides, spin, model, moment, aero), the ball as flown and the
    columns. Returns its path.
    """
    data = {
        'format': SIDECAR_FORMAT,
        'version': SIDECAR_VERSION,
        'csv': Path(csv_path).name,
        'columns': list(CSV_HEADER),
        'release': release.to_mapping(),
        'ball': asdict(ball),
        'model': release.model,
        'moment': release.moment,
        'aero': None if aero is None else aero.to_mapping(),
    }
    data.update(extra or {})
    path = sidecar_path(csv_path)
    path.write_text(json.dumps(data, indent=2, default=float) + '\n')
    return path


def read_sidecar(csv_path: str | Path) -> FlightInfo | None:
    """Read the flight a CSV holds from its sidecar; None without one; ValueError when bad."""
    path = sidecar_path(csv_path)
    if not path.exists():
        return None
    if path.stat().st_size > MAX_SIDECAR_BYTES:
        raise ValueError(f'{path}: sidecar larger than {MAX_SIDECAR_BYTES} bytes')
    try:
        data = json.loads(path.read_text())
        if not isinstance(data, dict) or data.get('format') != SIDECAR_FORMAT:
            raise ValueError('not a simulate sidecar')
        release = Release.from_mapping(data['release'])
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f'{path}: unreadable sidecar ({str(exc)[:120]})') from None
    ball, aero = resolve(release.preset(), release.model, release.aero_model())
    return FlightInfo(
        ball,
        release.ball,
        release.spin_rpm * RPM,
        release.model,
        release.moment,
        aero,
        Path(path).name,
    )


def order_flight(text: str) -> Flight:
    """Return the :class:`Flight` an order JSON describes, as the simulator flies it."""
    from ..requests import FlightOrder

    return FlightOrder.from_json(text).flight(DEFAULT_STEP)


def info_from_order(text: str, origin: str) -> FlightInfo:
    """Return the flight an order JSON (``football/flight/order``) describes; ValueError if bad."""
    from ..requests import FlightOrder  # the order's one parser (owned with the release path)

    order = FlightOrder.from_json(text)
    aero = AeroModel.from_mapping(order.aero) if order.model == 'full' else None
    ball, aero = resolve(order.ball(), order.model, aero)
    return FlightInfo(
        ball, order.ball_name, float(order.initial.spin), order.model, order.moment, aero, origin
    )


def load(path: str | Path) -> FlightRecord:
    """Load a CSV file from ``simulate``, or a bag (folder, or its .mcap/.db3 file)."""
    path = Path(path)
    if path.suffix == '.csv':
        return load_csv(path)
    if path.is_file() and path.suffix in ('.mcap', '.db3'):
        path = path.parent
    if not (path / 'metadata.yaml').exists():
        raise ValueError(f'{path}: neither a simulate CSV nor a rosbag2 folder with metadata.yaml')
    return load_bag(path)


def load_csv(path: Path) -> FlightRecord:
    """
    Load a simulate CSV: its 18 base columns (required, in order).

    Appended columns when present.
    """
    with open(path, newline='') as handle:
        header = next(csv.reader(handle), [])
    if tuple(header[: len(CSV_BASE_HEADER)]) != CSV_BASE_HEADER:
        raise ValueError(f'{path}: not a simulate CSV (header {",".join(header)[:80]})')
    d = np.loadtxt(path, delimiter=',', skiprows=1, ndmin=2)
    col = {name: i for i, name in enumerate(header)}

    def column(name: str) -> np.ndarray | None:
        return d[:, col[name]] if name in col else None

    return FlightRecord(
        t=d[:, 0],
        position=d[:, 1:4],
        velocity=d[:, 4:7],
        axis=d[:, 11:14],
        alpha=d[:, col['alpha']],
        beta=d[:, col['beta']],
        alpha_linear=d[:, col['alpha_linear']],
        beta_linear=d[:, col['beta_linear']],
        spin=column('spin'),
        source=str(path),
        alpha_quasi_steady=column('alpha_quasi_steady'),
        beta_quasi_steady=column('beta_quasi_steady'),
        info=read_sidecar(path),
    )


RELEASE_SLACK_S = 1e-4
"""A sample stamped this much [s] before the release found from the flight is still its first
(the release's estimate is a median of stamp less flight time: rounding, not ticks)."""


def release_stamp(stamps: np.ndarray, positions: np.ndarray, flight: Flight) -> float:
    """
    Return the stamp [s] at which a flight of ``flight`` was released.

    From its samples: ``stamps`` [s], ``positions`` (N, 3) [m] in ``field``. Each sample's
    flight time is read from its horizontal distance to the release point along the flight's
    own path (the distance grows all flight long); the median of stamp less that time over the
    first samples is returned. Without horizontal motion (a vertical throw): the first stamp.
    """
    path = flight.simulate(rate=1000.0, duration=60.0)
    start = path.positions[0, :2]
    distance = np.hypot(*(path.positions[:, :2] - start).T)
    first = min(len(stamps), 50)
    seen = np.hypot(*(positions[:first, :2] - start).T)
    if distance[-1] < 0.5 or np.any(np.diff(distance) <= 0.0):
        return float(stamps[0])
    inside = seen <= distance[-1]
    if not np.any(inside):
        return float(stamps[0])
    times = np.interp(seen[inside], distance, path.times)
    return float(np.median(stamps[:first][inside] - times))


def _last_flight(positions: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, int]:
    """
    Return (indices of the last flight's fresh samples, the index in ``starts`` it began at).

    ``positions`` in the order received. Repeats of a state (the held landing) are dropped; a
    flight begins at one of ``starts`` (where an order was received; the last one followed by
    two fresh samples), else (no orders: index -1) after the last held state.
    """
    fresh = np.ones(len(positions), bool)
    fresh[1:] = np.any(positions[1:] != positions[:-1], axis=1)
    index = np.flatnonzero(fresh)
    for k in range(len(starts) - 1, -1, -1):
        end = starts[k + 1] if k + 1 < len(starts) else len(positions)
        chosen = index[(index >= starts[k]) & (index < end)]
        if chosen.size >= 2:
            return chosen, k
    held = np.flatnonzero(~fresh[:-1] & fresh[1:]) + 1  # fresh again after a hold
    return index[index >= (held[-1] if held.size else 0)], -1


def load_bag(path: Path) -> FlightRecord:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import get_typestore, Stores

    odom, orders = [], []
    angles = {'aero_angles': [], 'aero_angles_linear': [], 'aero_angles_quasi_steady': []}
    suffixes = ('football/odom', 'football/flight/order') + tuple(f'football/{n}' for n in angles)
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic.endswith(suffixes)]
        if not any(c.topic.endswith(('football/odom', 'football/aero_angles')) for c in conns):
            raise ValueError(
                f'{path}: no football/odom or football/aero_angles messages in the bag'
            )
        for conn, bag_time, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.topic.endswith('flight/order'):
                orders.append((bag_time, msg.data))
                continue
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            if conn.topic.endswith('odom'):
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                v, w = msg.twist.twist.linear, msg.twist.twist.angular
                odom.append(
                    (stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, bag_time)
                )
            else:
                angles[conn.topic.rsplit('/', 1)[1]].append((stamp, msg.vector.x, msg.vector.y))
    odom_a = np.array(sorted(odom))
    aero_a, linear_a, quasi_a = (np.array(sorted(x)) for x in angles.values())
    if len(odom_a) < 2:
        raise ValueError(f'{path}: fewer than two football/odom messages')
    orders.sort(key=lambda o: o[0])
    received = odom_a[np.argsort(odom_a[:, 12], kind='stable')]  # the order they arrived in
    starts = np.searchsorted(received[:, 12], [o[0] for o in orders], 'right')
    keep, which = _last_flight(received[:, 1:4], starts)
    if keep.size < 2:
        raise ValueError(f'{path}: fewer than two football/odom messages in the last flight')
    odom_a = received[keep]
    odom_a = odom_a[np.argsort(odom_a[:, 0], kind='stable')]
    info, released = None, odom_a[0, 0]
    if which >= 0:
        text = orders[which][1]
        try:
            info = info_from_order(text, f'{Path(path).name}: football/flight/order')
            released = release_stamp(odom_a[:, 0], odom_a[:, 1:4], order_flight(text))
        except ValueError as exc:
            raise ValueError(
                f'{path}: unreadable football/flight/order message ({str(exc)[:120]})'
            ) from None
        # The first samples may reach the recorder before the order that caused them (two
        # publishers, no order between them): those received since the flight before,
        # stamped from the release on, are this flight's too.
        early = received[(starts[which - 1] if which > 0 else 0):starts[which]]
        early = early[early[:, 0] >= released - RELEASE_SLACK_S]
        if early.size:
            odom_a = np.concatenate([early, odom_a])
            odom_a = odom_a[np.argsort(odom_a[:, 0], kind='stable')]
    stamps = odom_a[:, 0]
    rot = frames.quaternion_to_matrix(odom_a[:, 4:8])
    velocity = np.einsum('nij,nj->ni', rot, odom_a[:, 8:11])  # body -> field

    def by_stamp(arr: np.ndarray, column: int) -> np.ndarray:
        if len(arr) == 0:
            return np.full(len(stamps), np.nan)
        index = {s: i for i, s in enumerate(arr[:, 0])}
        return np.array([arr[index[s], column] if s in index else np.nan for s in stamps])

    return FlightRecord(
        t=stamps - released,
        position=odom_a[:, 1:4],
        velocity=velocity,
        axis=rot[:, :, 0],
        alpha=by_stamp(aero_a, 1),
        beta=by_stamp(aero_a, 2),
        alpha_linear=by_stamp(linear_a, 1),
        beta_linear=by_stamp(linear_a, 2),
        spin=odom_a[:, 11],
        alpha_quasi_steady=by_stamp(quasi_a, 1) if len(quasi_a) else None,
        beta_quasi_steady=by_stamp(quasi_a, 2) if len(quasi_a) else None,
        source=str(path),
        info=info,
    )


def record_from_trajectory(
    trajectory, info: FlightInfo, source: str = 'simulated'
) -> FlightRecord:
    """
    Make a :class:`FlightRecord` of a :class:`football_ros.physics.flight.Trajectory`.

    No file.
    """
    angles, linear, quasi = (
        trajectory.aero_angles,
        trajectory.aero_angles_linear,
        trajectory.aero_angles_quasi_steady,
    )
    return FlightRecord(
        t=trajectory.times,
        position=trajectory.positions,
        velocity=trajectory.velocities,
        axis=trajectory.axes,
        alpha=angles[:, 0],
        beta=angles[:, 1],
        alpha_linear=linear[:, 0],
        beta_linear=linear[:, 1],
        spin=trajectory.spin,
        source=source,
        alpha_quasi_steady=quasi[:, 0],
        beta_quasi_steady=quasi[:, 1],
        info=info,
    )
