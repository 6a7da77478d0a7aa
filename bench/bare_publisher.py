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
Baseline for bench/node_benchmark.py.

A bare rclpy node that publishes what the simulator publishes in flight (default parameters),
prebuilt, only the stamps changing, from a plain rclpy timer at the same rate: the six state
messages and /tf every tick, the RViz markers (a full 500-point trail) at 30 Hz.
"""

import sys

from football_ros.nodes import messages as mb
from football_ros.nodes import qos
from football_ros.physics import Flight, Release
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import rclpy
from rclpy.executors import ExternalShutdownException
from visualization_msgs.msg import MarkerArray

MARKER_RATE = 30.0  # the simulator's default marker_rate [Hz]
TRAIL = 500  # the simulator's default trail_length


def main() -> None:
    rate = float(sys.argv[1]) if len(sys.argv) > 1 else 1000.0
    rclpy.init()
    node = rclpy.create_node('bare_publisher')
    flight = Flight.from_release(Release())
    sample = flight.sample(1.0)
    stamp0 = mb.time_msg(0)
    state = mb.StateMessages()
    state.fill(sample, stamp0, 'field', 'football')
    trail = [mb.point(flight.sample(1.0 + 1e-3 * k).position) for k in range(TRAIL)]
    pubs = [
        (node.create_publisher(cls, topic, qos.STATE), msg, [msg.header])
        for topic, cls, msg in (
            (qos.POSE, PoseStamped, state.pose),
            (qos.ODOM, Odometry, state.odom),
            (qos.SPIN_AXIS, Vector3Stamped, state.spin_axis),
            (qos.AERO_ANGLES, Vector3Stamped, state.aero_angles),
            (qos.AERO_ANGLES_LINEAR, Vector3Stamped, state.aero_angles_linear),
            (qos.AERO_ANGLES_QUASI_STEADY, Vector3Stamped, state.aero_angles_quasi_steady),
        )
    ]
    if mb.TFMessage is not None:
        tf = mb.tf_message(sample, stamp0, 'field', 'football')
        pubs.append(
            (
                node.create_publisher(mb.TFMessage, qos.TF, qos.TF_QOS),
                tf,
                [t.header for t in tf.transforms],
            )
        )
    markers = mb.markers(
        sample, trail, stamp0, 'field', flight.ball.length, flight.ball.diameter
    )
    markers_pub = node.create_publisher(MarkerArray, qos.MARKERS, qos.MARKERS_QOS)
    every = max(1, round(rate / MARKER_RATE))
    ticks = [0]

    def tick() -> None:
        stamp = node.get_clock().now().to_msg()
        for pub, msg, headers in pubs:
            for hdr in headers:
                hdr.stamp = stamp
            pub.publish(msg)
        ticks[0] += 1
        if ticks[0] % every == 0:
            for marker in markers.markers:
                marker.header.stamp = stamp
            markers_pub.publish(markers)

    node.create_timer(1.0 / rate, tick)
    print('ready', flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
