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
football_ros.tools.demo's live table: flight times, rows only after the header, the landing last.

The messages are plain stand-ins (no ROS): the pose and the angles of each tick, stamped as a
stalled simulator stamps them.
"""

from types import SimpleNamespace as NS

from football_ros.physics import Flight, Release
from football_ros.tools import demo
import numpy as np
import pytest


def _stamp(seconds: float) -> NS:
    ns = int(round(seconds * 1e9))
    return NS(stamp=NS(sec=ns // 10**9, nanosec=ns % 10**9))


@pytest.mark.parametrize('seed', range(3))
def test_rows_at_flight_time_after_the_header_landing_last(monkeypatch, seed):
    rng = np.random.default_rng(seed)
    release = Release(speed=float(rng.uniform(15, 30)), elevation_deg=float(rng.uniform(10, 40)))
    tr = Flight.from_release(release).simulate(rate=200.0, duration=10.0)
    said = []
    monkeypatch.setattr(demo, '_say', said.append)
    table = demo._Table(Flight.from_release(release))
    n = len(tr.times)
    late = int(rng.integers(0, 4))
    stall = int(rng.integers(10, n // 2))
    rows = [i for i in range(late, n) if not stall <= i < stall + 150]  # 0.75 s stalled
    released = 1000.0 + float(rng.uniform(0, 1))
    for k, i in enumerate(rows + [n - 1] * 3):  # the landed state held after the landing
        stamp = _stamp(released + tr.times[i] + 0.3 * (k >= len(rows)) * (k - len(rows) + 1))
        p, a = tr.positions[i], tr.aero_angles[i]
        pose = NS(header=stamp, pose=NS(position=NS(x=p[0], y=p[1], z=p[2])))
        angles = NS(header=stamp, vector=NS(x=a[0], y=a[1], z=a[2]))
        first, second = (pose, angles) if k % 2 else (angles, pose)
        (table.on_pose if first is pose else table.on_angles)(first)
        (table.on_pose if second is pose else table.on_angles)(second)
        if k == 5:
            assert said == []  # nothing before the header
            table.show_header()
    table.finish()
    assert said[0].split() == ['t', '[s]', 'x', '[m]', 'y', '[m]', 'z', '[m]', 'alpha', '[deg]',
                               'beta', '[deg]']
    times = np.array([float(line.split()[0]) for line in said[1:]])
    xs = np.array([float(line.split()[1]) for line in said[1:]])
    assert times[0] == pytest.approx(tr.times[late], abs=0.006)  # flight time, not 0
    assert np.all(np.diff(times) > 0)
    assert times[-1] == pytest.approx(tr.times[-1], abs=0.006)  # the landing, last
    assert xs[-1] == pytest.approx(tr.positions[-1, 0], abs=0.006)
    assert np.all(np.diff(np.floor(times[:-1] / 0.1 + 1e-6)) >= 1)  # a row per 0.1 s at most
