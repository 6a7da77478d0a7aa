"""Load a flight from a recorded bag (rosbags) or a ``football-ros simulate`` CSV, no ROS needed.

Both give a :class:`FlightRecord` of arrays in ``field``, SI units, t = 0 at the release.
A bag may hold several flights: the last one is taken (flights are split where the state
stream pauses for more than ten publish periods); the landed state the simulator republishes
after the landing is dropped.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..physics import frames
from ..physics.flight import CSV_HEADER


@dataclass(frozen=True)
class FlightRecord:
    """t (N,) [s], position, velocity, axis (N, 3), alpha, beta, alpha_linear, beta_linear (N,)
    [rad]; spin (N,) [rad/s] about the axis when known (bags), else None."""

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


def load(path: str | Path) -> FlightRecord:
    """A CSV file from ``simulate``, or a bag (folder, or its .mcap/.db3 file)."""
    path = Path(path)
    if path.suffix == ".csv":
        return load_csv(path)
    if path.is_file() and path.suffix in (".mcap", ".db3"):
        path = path.parent
    if not (path / "metadata.yaml").exists():
        raise ValueError(f"{path}: neither a simulate CSV nor a rosbag2 folder with metadata.yaml")
    return load_bag(path)


def load_csv(path: Path) -> FlightRecord:
    with open(path, newline="") as handle:
        header = next(csv.reader(handle))
    if tuple(header) != CSV_HEADER:
        raise ValueError(f"{path}: not a simulate CSV (header {','.join(header)[:80]})")
    d = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    col = {name: i for i, name in enumerate(CSV_HEADER)}
    return FlightRecord(t=d[:, 0], position=d[:, 1:4], velocity=d[:, 4:7], axis=d[:, 11:14],
                        alpha=d[:, col["alpha"]], beta=d[:, col["beta"]],
                        alpha_linear=d[:, col["alpha_linear"]], beta_linear=d[:, col["beta_linear"]],
                        spin=None, source=str(path))


def _last_flight(stamps: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Indices of the last flight: drop repeats of a state (the held landing), split at pauses."""
    fresh = np.ones(len(stamps), bool)
    fresh[1:] = np.any(positions[1:] != positions[:-1], axis=1)
    index = np.flatnonzero(fresh)
    gaps = np.diff(stamps[index])
    if gaps.size == 0:
        return index
    starts = np.flatnonzero(gaps > 10 * np.median(gaps)) + 1
    return index[starts[-1]:] if starts.size else index


def load_bag(path: Path) -> FlightRecord:
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    odom, aero, linear = [], [], []
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections
                 if c.topic.endswith(("football/odom", "football/aero_angles", "football/aero_angles_linear"))]
        if not conns:
            raise ValueError(f"{path}: no football/odom or football/aero_angles messages in the bag")
        for conn, _t, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
            if conn.topic.endswith("odom"):
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                v, w = msg.twist.twist.linear, msg.twist.twist.angular
                odom.append((stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x))
            elif conn.topic.endswith("aero_angles"):
                aero.append((stamp, msg.vector.x, msg.vector.y))
            else:
                linear.append((stamp, msg.vector.x, msg.vector.y))
    odom_a, aero_a, linear_a = (np.array(sorted(x)) for x in (odom, aero, linear))
    if len(odom_a) < 2:
        raise ValueError(f"{path}: fewer than two football/odom messages")
    keep = _last_flight(odom_a[:, 0], odom_a[:, 1:4])
    odom_a = odom_a[keep]
    stamps = odom_a[:, 0]
    rot = frames.quaternion_to_matrix(odom_a[:, 4:8])
    velocity = np.einsum("nij,nj->ni", rot, odom_a[:, 8:11])  # body -> field

    def by_stamp(arr: np.ndarray, column: int) -> np.ndarray:
        if len(arr) == 0:
            return np.full(len(stamps), np.nan)
        index = {s: i for i, s in enumerate(arr[:, 0])}
        return np.array([arr[index[s], column] if s in index else np.nan for s in stamps])

    return FlightRecord(t=stamps - stamps[0], position=odom_a[:, 1:4], velocity=velocity, axis=rot[:, :, 0],
                        alpha=by_stamp(aero_a, 1), beta=by_stamp(aero_a, 2),
                        alpha_linear=by_stamp(linear_a, 1), beta_linear=by_stamp(linear_a, 2),
                        spin=odom_a[:, 11], source=str(path))
