"""Simulator + release node, and optionally the recorder.

    ros2 launch football_ros football.launch.py
    ros2 launch football_ros football.launch.py record:=true publish_rate:=1000.0
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    default_params = os.path.join(get_package_share_directory("football_ros"), "config", "football.yaml")
    params_file = LaunchConfiguration("params_file")
    publish_rate = LaunchConfiguration("publish_rate")
    return LaunchDescription([
        DeclareLaunchArgument("params_file", default_value=default_params,
                              description="YAML with the nodes' parameters"),
        DeclareLaunchArgument("publish_rate", default_value="100.0",
                              description="simulator publish rate [Hz]"),
        DeclareLaunchArgument("record", default_value="false", description="also run the recorder"),
        Node(package="football_ros", executable="simulator", name="football_simulator", output="screen",
             parameters=[params_file, {"publish_rate": publish_rate}]),
        Node(package="football_ros", executable="release", name="football_release", output="screen",
             parameters=[params_file]),
        Node(package="football_ros", executable="recorder", name="football_recorder", output="screen",
             parameters=[params_file], condition=IfCondition(LaunchConfiguration("record"))),
    ])
