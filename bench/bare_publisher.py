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
