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
football_ros.tools.flightdata: a bag's last flight by its order and its flight time.

A stalled simulator skips ticks (a pause in the stamps, the ball further on after it) and may
skip the first ones; an earlier flight may precede the last one in the bag. The record holds
the whole last flight, each sample at its true flight time.
"""

from football_ros.physics import frames, Release
from football_ros.physics.flight import Flight
from football_ros.requests import FlightOrder
from football_ros.tools import flightdata
import numpy as np
import pytest


def _write(path, flights):
    """
    Write a rosbag2 folder (rosbags, no ROS) of ``flights``.

    Per flight (trajectory, rows kept, order JSON or None, release stamp [s]): its order, then
    its football/odom rows, received in that order.
    """
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import get_typestore, Stores

    ts = get_typestore(Stores.ROS2_JAZZY)
    T = ts.types
    received = 1
    with Writer(path, version=8) as writer:
        odom = writer.add_connection('/football/odom', 'nav_msgs/msg/Odometry', typestore=ts)
        string = 'std_msgs/msg/String'
        order = writer.add_connection('/football/flight/order', string, typestore=ts)
        for trajectory, rows, order_json, released in flights:
            if order_json is not None:
                writer.write(order, received, ts.serialize_cdr(T[string](data=order_json), string))
                received += 1
            rot = frames.quaternion_to_matrix(trajectory.orientations)
            body_v = np.einsum('nji,nj->ni', rot, trajectory.velocities)
            for i in rows:
                ns = int(round((released + trajectory.times[i]) * 1e9))
                stamp = T['builtin_interfaces/msg/Time'](sec=ns // 10**9, nanosec=ns % 10**9)
                q = trajectory.orientations[i]
                vec = lambda a: T['geometry_msgs/msg/Vector3'](*map(float, a))  # noqa: E731
                pose = T['geometry_msgs/msg/Pose'](
                    position=T['geometry_msgs/msg/Point'](*map(float, trajectory.positions[i])),
                    orientation=T['geometry_msgs/msg/Quaternion'](x=q[0], y=q[1], z=q[2], w=q[3]),
                )
                msg = T['nav_msgs/msg/Odometry'](
                    header=T['std_msgs/msg/Header'](stamp=stamp, frame_id='field'),
                    child_frame_id='football',
                    pose=T['geometry_msgs/msg/PoseWithCovariance'](pose=pose,
                                                                   covariance=np.zeros(36)),
                    twist=T['geometry_msgs/msg/TwistWithCovariance'](
                        twist=T['geometry_msgs/msg/Twist'](
                            linear=vec(body_v[i]), angular=vec([trajectory.spin[i], 0, 0])),
                        covariance=np.zeros(36),
                    ),
                )
                writer.write(odom, received, ts.serialize_cdr(msg, 'nav_msgs/msg/Odometry'))
                received += 1


def _flight(release):
    return Flight.from_release(release).simulate(rate=100.0, duration=10.0)


@pytest.mark.parametrize('seed', range(4))
def test_a_stalled_flight_after_another_is_drawn_whole_at_its_flight_times(tmp_path, seed):
    rng = np.random.default_rng(seed)
    first = Release(speed=15.0, elevation_deg=20.0)
    last = Release(speed=float(rng.uniform(18.0, 30.0)), elevation_deg=float(rng.uniform(15, 40)),
                   azimuth_deg=float(rng.uniform(-20, 20)), position=(0.0, 0.0, 1.8))
    tr0, tr = _flight(first), _flight(last)
    n = len(tr.times)
    skipped = int(rng.integers(1, 6))  # the first ticks, late
    stall = slice(int(rng.integers(skipped + 5, n // 2)), None)
    stall = range(stall.start, stall.start + int(rng.integers(30, 120)))  # 0.3-1.2 s of ticks
    rows = [i for i in range(skipped, n) if i not in stall]
    held = [n - 1] * 3  # the landed state, held
    order0 = FlightOrder.from_release('first', first).to_json()
    order = FlightOrder.from_release('last', last).to_json()
    _write(tmp_path / 'bag', [(tr0, list(range(len(tr0.times))) + [len(tr0.times) - 1] * 3,
                               order0, 100.0),
                              (tr, rows + held, order, 200.0)])
    record = flightdata.load(tmp_path / 'bag')
    assert len(record.t) == len(rows)  # the whole last flight: no split at the stall
    assert np.max(np.abs(record.position - tr.positions[rows])) < 1e-12
    # each sample at its own flight time, the first ones skipped included
    assert np.max(np.abs(record.t - tr.times[rows])) < 2e-3
    assert record.t[-1] == pytest.approx(tr.times[-1], abs=2e-3)  # the landing
    assert record.info.ball_name == 'american'


def test_without_orders_the_last_flight_begins_after_the_held_landing(tmp_path):
    tr0, tr = _flight(Release(speed=12.0)), _flight(Release(speed=20.0))
    held0 = [len(tr0.times) - 1] * 4
    _write(tmp_path / 'bag', [(tr0, list(range(len(tr0.times))) + held0, None, 100.0),
                              (tr, list(range(len(tr.times))), None, 200.0)])
    record = flightdata.load(tmp_path / 'bag')
    assert len(record.t) == len(tr.times) and record.t[0] == 0.0
    assert np.max(np.abs(record.position - tr.positions)) < 1e-12
    assert record.info is None
