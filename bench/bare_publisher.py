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

A bare rclpy node that publishes the simulator's five state messages (prebuilt, only the stamp
changes) from a plain rclpy timer at the same rate.
"""

import sys

from football_ros.nodes import qos
from geometry_msgs.msg import PoseStamped, Vector3Stamped
from nav_msgs.msg import Odometry
import rclpy
from rclpy.executors import ExternalShutdownException


def main() -> None:
    rate = float(sys.argv[1]) if len(sys.argv) > 1 else 1000.0
    rclpy.init()
    node = rclpy.create_node('bare_publisher')
    pubs = [
        (node.create_publisher(cls, topic, qos.STATE), cls())
        for topic, cls in (
            (qos.POSE, PoseStamped),
            (qos.ODOM, Odometry),
            (qos.SPIN_AXIS, Vector3Stamped),
            (qos.AERO_ANGLES, Vector3Stamped),
            (qos.AERO_ANGLES_LINEAR, Vector3Stamped),
        )
    ]
    for _, msg in pubs:
        msg.header.frame_id = 'field'

    def tick() -> None:
        stamp = node.get_clock().now().to_msg()
        for pub, msg in pubs:
            msg.header.stamp = stamp
            pub.publish(msg)

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
