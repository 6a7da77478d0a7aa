"""Simulator and release node; optionally the recorder and RViz; optionally in a namespace.

    ros2 launch football_ros football.launch.py
    ros2 launch football_ros football.launch.py record:=true rviz:=true
    ros2 launch football_ros football.launch.py namespace:=team1 publish_rate:=1000
    ros2 launch football_ros football.launch.py use_sim_time:=true

Parameters come from ``params_file`` (keys ``/**/NODE_NAME``, so they apply in any namespace).
An argument left empty overrides nothing: ``publish_rate`` only replaces the file's value when
given (an integer is taken as Hz like a float). ``use_sim_time:=true`` makes the simulator the
clock source (``publish_clock``) and the release node, the recorder and RViz follow /clock.
/tf is global (tf2 convention): with several namespaced simulators give each its own
``child_frame_id`` in its params file.
"""

import math
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, OpaqueFunction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace
from launch_ros.parameter_descriptions import ParameterValue

PACKAGE = 'football_ros'


def _flag(context, name):
    """A boolean launch argument, read as launch's conditions read them."""
    text = LaunchConfiguration(name).perform(context).strip().lower()
    if text not in ('true', 'false', '1', '0'):
        raise ValueError(f"launch argument '{name}' must be true or false, got '{text}'")
    return text in ('true', '1')


def simulator_overrides(context):
    """Simulator parameters set by launch arguments (on top of the params file)."""
    overrides = {}
    rate = LaunchConfiguration('publish_rate').perform(context).strip()
    if rate:
        try:
            value = float(rate)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise ValueError(f"launch argument 'publish_rate' must be a number [Hz], got '{rate[:80]}'")
        overrides['publish_rate'] = value
    if _flag(context, 'use_sim_time'):
        overrides['publish_clock'] = True
    return overrides


def _simulator(context, *args, **kwargs):
    overrides = simulator_overrides(context)
    parameters = [LaunchConfiguration('params_file')] + ([overrides] if overrides else [])
    return [Node(package=PACKAGE, executable='simulator', name='football_simulator',
                 output='screen', parameters=parameters)]


def generate_launch_description():
    share = get_package_share_directory(PACKAGE)
    params_file = LaunchConfiguration('params_file')
    sim_time = {'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'), value_type=bool)}
    return LaunchDescription([
        DeclareLaunchArgument('params_file',
                              default_value=os.path.join(share, 'config', 'football.yaml'),
                              description="YAML with the nodes' parameters (/**/NODE_NAME keys)"),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of every node and relative topic'),
        DeclareLaunchArgument('publish_rate', default_value='',
                              description='simulator publish rate [Hz]; empty = params file'),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='simulator publishes /clock; the other nodes follow it'),
        DeclareLaunchArgument('record', default_value='false', description='also run the recorder'),
        DeclareLaunchArgument('rviz', default_value='false', description='also start rviz2'),
        DeclareLaunchArgument('rviz_config',
                              default_value=os.path.join(share, 'rviz', 'football.rviz'),
                              description='RViz configuration'),
        GroupAction([
            PushRosNamespace(LaunchConfiguration('namespace')),
            OpaqueFunction(function=_simulator),
            Node(package=PACKAGE, executable='release', name='football_release',
                 output='screen', parameters=[params_file, sim_time]),
            Node(package=PACKAGE, executable='recorder', name='football_recorder',
                 output='screen', parameters=[params_file, sim_time],
                 condition=IfCondition(LaunchConfiguration('record'))),
            Node(package='rviz2', executable='rviz2', name='rviz2', output='screen',
                 arguments=['-d', LaunchConfiguration('rviz_config')], parameters=[sim_time],
                 condition=IfCondition(LaunchConfiguration('rviz'))),
        ]),
    ])
