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
Simulator and release node; optionally the recorder and RViz; optionally in a namespace.

    ros2 launch football_ros football.launch.py
    ros2 launch football_ros football.launch.py record:=true rviz:=true
    ros2 launch football_ros football.launch.py namespace:=team1 publish_rate:=1000
    ros2 launch football_ros football.launch.py use_sim_time:=true
    ros2 launch football_ros football.launch.py tracker:=true rviz:=true

Parameters come from ``params_file`` (keys ``/**/NODE_NAME``, so they apply in any namespace).
An argument left empty overrides nothing: ``publish_rate`` only replaces the file's value when
given (an integer is taken as Hz like a float). ``use_sim_time:=true`` makes the simulator the
clock source (``publish_clock``) and the release node, the recorder and RViz follow /clock.
``tracker:=true`` also runs the tracker and turns the simulator's camera on (``camera_rate``,
default 60 Hz; a given ``camera_rate`` always replaces the file's ``observation_rate``).
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
DEFAULT_CAMERA_RATE = 60.0


def _flag(context, name):
    """Read a boolean launch argument as launch's conditions read them."""
    text = LaunchConfiguration(name).perform(context).strip().lower()
    if text not in ('true', 'false', '1', '0'):
        raise ValueError(f"launch argument '{name}' must be true or false, got '{text}'")
    return text in ('true', '1')


def _rate(context, name):
    """Read a rate launch argument [Hz] as a float, or None when left empty."""
    text = LaunchConfiguration(name).perform(context).strip()
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"launch argument '{name}' must be a number [Hz], got '{text[:80]}'")
    return value


def simulator_overrides(context):
    """Return the simulator parameters set by launch arguments (on top of the params file)."""
    overrides = {}
    rate = _rate(context, 'publish_rate')
    if rate is not None:
        overrides['publish_rate'] = rate
    if _flag(context, 'use_sim_time'):
        overrides['publish_clock'] = True
    camera = _rate(context, 'camera_rate')
    if camera is None and _flag(context, 'tracker'):
        camera = DEFAULT_CAMERA_RATE
    if camera is not None:
        overrides['observation_rate'] = camera
    return overrides


def _simulator(context, *args, **kwargs):
    overrides = simulator_overrides(context)
    parameters = [LaunchConfiguration('params_file')] + ([overrides] if overrides else [])
    return [
        Node(
            package=PACKAGE,
            executable='simulator',
            name='football_simulator',
            output='screen',
            parameters=parameters,
        )
    ]


def generate_launch_description():
    share = get_package_share_directory(PACKAGE)
    params_file = LaunchConfiguration('params_file')
    sim_time = {
        'use_sim_time': ParameterValue(LaunchConfiguration('use_sim_time'), value_type=bool)
    }
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                'params_file',
                default_value=os.path.join(share, 'config', 'football.yaml'),
                description="YAML with the nodes' parameters (/**/NODE_NAME keys)",
            ),
            DeclareLaunchArgument(
                'namespace',
                default_value='',
                description='namespace of every node and relative topic',
            ),
            DeclareLaunchArgument(
                'publish_rate',
                default_value='',
                description='simulator publish rate [Hz]; empty = params file',
            ),
            DeclareLaunchArgument(
                'use_sim_time',
                default_value='false',
                description='simulator publishes /clock; the other nodes follow it',
            ),
            DeclareLaunchArgument(
                'record', default_value='false', description='also run the recorder'
            ),
            DeclareLaunchArgument(
                'tracker',
                default_value='false',
                description="also run the tracker (and the simulator's camera)",
            ),
            DeclareLaunchArgument(
                'camera_rate',
                default_value='',
                description='simulated camera frames per second [Hz]; empty = '
                'params file, or 60 with tracker:=true',
            ),
            DeclareLaunchArgument('rviz', default_value='false', description='also start rviz2'),
            DeclareLaunchArgument(
                'planner', default_value='false', description='also run the throw planner'
            ),
            DeclareLaunchArgument(
                'rviz_config',
                default_value=os.path.join(share, 'rviz', 'football.rviz'),
                description='RViz configuration',
            ),
            GroupAction(
                [
                    PushRosNamespace(LaunchConfiguration('namespace')),
                    OpaqueFunction(function=_simulator),
                    Node(
                        package=PACKAGE,
                        executable='release',
                        name='football_release',
                        output='screen',
                        parameters=[params_file, sim_time],
                    ),
                    Node(
                        package=PACKAGE,
                        executable='tracker',
                        name='football_tracker',
                        output='screen',
                        parameters=[params_file, sim_time],
                        condition=IfCondition(LaunchConfiguration('tracker')),
                    ),
                    Node(
                        package=PACKAGE,
                        executable='planner',
                        name='football_planner',
                        output='screen',
                        parameters=[params_file, sim_time],
                        condition=IfCondition(LaunchConfiguration('planner')),
                    ),
                    Node(
                        package=PACKAGE,
                        executable='recorder',
                        name='football_recorder',
                        output='screen',
                        parameters=[params_file, sim_time],
                        condition=IfCondition(LaunchConfiguration('record')),
                    ),
                    Node(
                        package='rviz2',
                        executable='rviz2',
                        name='rviz2',
                        output='screen',
                        arguments=['-d', LaunchConfiguration('rviz_config')],
                        parameters=[sim_time],
                        condition=IfCondition(LaunchConfiguration('rviz')),
                    ),
                ]
            ),
        ]
    )
