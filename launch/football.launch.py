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
Simulator and release node; optionally recorder, tracker, planner, RViz, Foxglove viewer.

    ros2 launch football_ros football.launch.py
    ros2 launch football_ros football.launch.py record:=true rviz:=true
    ros2 launch football_ros football.launch.py namespace:=team1 publish_rate:=1000
    ros2 launch football_ros football.launch.py use_sim_time:=true
    ros2 launch football_ros football.launch.py tracker:=true rviz:=true
    ros2 launch football_ros football.launch.py planner:=true       # + the throw planner
    ros2 launch football_ros football.launch.py view:=true          # + Foxglove viewer (8765)
    ros2 launch football_ros football.launch.py tracker:=true camera_rig:=config/rig_stereo.yaml

Parameters come from ``params_file`` (keys ``/**/NODE_NAME``, so they apply in any namespace).
An argument left empty overrides nothing: ``publish_rate`` only replaces the file's value when
given (an integer is taken as Hz like a float). ``use_sim_time:=true`` makes the simulator the
clock source (``publish_clock``) and the release node, the recorder and RViz follow /clock.
``tracker:=true`` also runs the tracker and turns the simulator's camera on (``camera_rate``,
default 60 Hz; a given ``camera_rate`` always replaces the file's ``observation_rate``).
``camera_rig:=FILE`` (config/rig_*.yaml) gives the simulator a rig of calibrated cameras
(CameraInfo and Detection2DArray per camera) and, with ``tracker:=true``, has the tracker fuse
all of its cameras' pixels instead of the 3D camera (which ``camera_rate`` still turns on).
/tf is global (tf2 convention): with several namespaced simulators give each its own
``child_frame_id`` in its params file.

Every argument is checked before any node starts (flags true/false, rates finite and inside
the simulator's own parameter ranges, the params file readable): a bad one ends the launch
with one error naming it and nothing running. ``rviz:=true`` without rviz2 installed starts
the rest with a warning. The simulator and the release node end the launch when either exits,
so that no node is left running alone.

Security (README, section Security): ``security:=true`` starts every football_ros node in its
SROS2 enclave (``--ros-args --enclave /football_ros/<node>``, the enclaves of
security/football_ros_policy.xml); ``keystore:=DIR`` also sets ROS_SECURITY_KEYSTORE=DIR,
ROS_SECURITY_ENABLE=true and ROS_SECURITY_STRATEGY=Enforce for them. ``allow_reconfigure:=true``
lets the guarded parameters of the simulator and the release node change at run time (empty:
the params file decides; its default is false).
"""

import math
import os

from ament_index_python.packages import get_package_share_directory, PackageNotFoundError
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, LogInfo, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace

PACKAGE = 'football_ros'
DEFAULT_CAMERA_RATE = 60.0
FLAGS = ('use_sim_time', 'record', 'tracker', 'planner', 'rviz', 'view', 'security')
ENCLAVE_ROOT = '/football_ros'
"""Enclaves of the nodes: ENCLAVE_ROOT/<executable> (security/football_ros_policy.xml)."""


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


def _ranged(context, name, parameter):
    """Return a rate argument checked against the simulator parameter it sets, or None."""
    value = _rate(context, name)
    if value is None:
        return None
    from football_ros.nodes.simulator import SimulatorNode  # the one table of the ranges

    [spec] = [s for s in SimulatorNode.PARAMETERS if s.name == parameter]
    lo, hi = spec.limits
    if not lo <= value <= hi:
        raise ValueError(
            f"launch argument '{name}' must be in [{lo:g}, {hi:g}] Hz "
            f"(the simulator's {parameter}), got {value:g}"
        )
    return value


def simulator_overrides(context):
    """Return the simulator parameters set by launch arguments (on top of the params file)."""
    overrides = {}
    rate = _ranged(context, 'publish_rate', 'publish_rate')
    if rate is not None:
        overrides['publish_rate'] = rate
    if _flag(context, 'use_sim_time'):
        overrides['publish_clock'] = True
    camera = _ranged(context, 'camera_rate', 'observation_rate')
    if camera is None and _flag(context, 'tracker') and not camera_rig(context):
        camera = DEFAULT_CAMERA_RATE
    if camera is not None:
        overrides['observation_rate'] = camera
    rig = camera_rig(context)
    if rig:
        overrides['camera_rig'] = rig[0]
    return overrides


def camera_rig(context):
    """Return (absolute path, camera names) of the ``camera_rig`` argument, or None (empty)."""
    text = LaunchConfiguration('camera_rig').perform(context).strip()
    if not text:
        return None
    from football_ros.estimation.rig import load_rig  # the one reader of rig files

    try:
        rig = load_rig(text)
    except ValueError as exc:
        raise ValueError(f"launch argument 'camera_rig': {exc}") from None
    return os.path.abspath(text), [camera.name for camera in rig]


def _optional_flag(context, name):
    """Read a boolean launch argument that may be left empty (None: not given)."""
    if not LaunchConfiguration(name).perform(context).strip():
        return None
    return _flag(context, name)


def security_options(context, executable):
    """Return the Node keyword arguments that start ``executable`` in its enclave, or {}."""
    keystore = LaunchConfiguration('keystore').perform(context).strip()
    if not (_flag(context, 'security') or keystore):
        return {}
    options = {'ros_arguments': ['--enclave', f'{ENCLAVE_ROOT}/{executable}']}
    if keystore:
        if not os.path.isdir(keystore):
            raise ValueError(f"launch argument 'keystore': no folder '{keystore[:200]}'")
        options['additional_env'] = {
            'ROS_SECURITY_KEYSTORE': keystore,
            'ROS_SECURITY_ENABLE': 'true',
            'ROS_SECURITY_STRATEGY': 'Enforce',
        }
    return options


def _rviz_available():
    try:
        get_package_share_directory('rviz2')
    except PackageNotFoundError:
        return False
    return True


def _nodes(context, *args, **kwargs):
    """Check every argument, then return the nodes to start (all or nothing)."""
    flags = {name: _flag(context, name) for name in FLAGS}
    overrides = simulator_overrides(context)
    reconfigure = _optional_flag(context, 'allow_reconfigure')
    guard = {} if reconfigure is None else {'allow_reconfigure': reconfigure}
    overrides.update(guard)
    secure = {
        name: security_options(context, name)
        for name in ('simulator', 'release', 'tracker', 'planner', 'recorder', 'view')
    }
    params_file = LaunchConfiguration('params_file').perform(context)
    if not os.path.isfile(params_file) or not os.access(params_file, os.R_OK):
        raise ValueError(f"launch argument 'params_file': cannot read '{params_file[:200]}'")
    sim_time = {'use_sim_time': flags['use_sim_time']}
    ending = {'on_exit': Shutdown(reason='a football_ros core node exited')}
    actions = [
        Node(
            package=PACKAGE,
            executable='simulator',
            name='football_simulator',
            output='screen',
            parameters=[params_file] + ([overrides] if overrides else []),
            **ending,
            **secure['simulator'],
        ),
        Node(
            package=PACKAGE,
            executable='release',
            name='football_release',
            output='screen',
            parameters=[params_file, dict(sim_time, **guard)],
            **ending,
            **secure['release'],
        ),
    ]
    rig = camera_rig(context)
    cameras = {'cameras': rig[1]} if rig else {}
    for flag, executable, name, extra in (
        ('tracker', 'tracker', 'football_tracker', cameras),
        ('planner', 'planner', 'football_planner', {}),
        ('record', 'recorder', 'football_recorder', {}),
        ('view', 'view', 'football_view', {}),
    ):
        if flags[flag]:
            actions.append(
                Node(
                    package=PACKAGE,
                    executable=executable,
                    name=name,
                    output='screen',
                    parameters=[params_file, dict(sim_time, **guard, **extra)],
                    **secure[executable],
                )
            )
    if flags['rviz'] and not _rviz_available():
        actions.append(LogInfo(msg='WARNING: rviz:=true, but rviz2 is not installed: not started'))
    elif flags['rviz']:
        actions.append(
            Node(
                package='rviz2',
                executable='rviz2',
                name='rviz2',
                output='screen',
                arguments=['-d', LaunchConfiguration('rviz_config').perform(context)],
                parameters=[sim_time],
            )
        )
    return actions


def generate_launch_description():
    share = get_package_share_directory(PACKAGE)
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
            DeclareLaunchArgument(
                'camera_rig',
                default_value='',
                description='camera rig file (config/rig_*.yaml) for the simulator; with '
                "tracker:=true the tracker fuses its cameras' pixels; empty = params file",
            ),
            DeclareLaunchArgument(
                'rviz',
                default_value='false',
                description='also start rviz2 (a warning, not an error, without it)',
            ),
            DeclareLaunchArgument(
                'planner', default_value='false', description='also run the throw planner'
            ),
            DeclareLaunchArgument(
                'view',
                default_value='false',
                description='also run the Foxglove viewer (football-ros view; its host and '
                'port: params file)',
            ),
            DeclareLaunchArgument(
                'security',
                default_value='false',
                description='start every football_ros node in its SROS2 enclave '
                f'({ENCLAVE_ROOT}/<node>)',
            ),
            DeclareLaunchArgument(
                'keystore',
                default_value='',
                description='SROS2 keystore: also enable and enforce security for the nodes',
            ),
            DeclareLaunchArgument(
                'allow_reconfigure',
                default_value='',
                description='guarded parameters changeable at run time (true/false); '
                'empty = params file (false)',
            ),
            DeclareLaunchArgument(
                'rviz_config',
                default_value=os.path.join(share, 'rviz', 'football.rviz'),
                description='RViz configuration',
            ),
            GroupAction(
                [
                    PushRosNamespace(LaunchConfiguration('namespace')),
                    OpaqueFunction(function=_nodes),
                ]
            ),
        ]
    )
