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
The package's programs: the one list of its nodes and ROS commands (no imports).

setup.py makes the console scripts (``ros2 run football_ros <node>``) from :data:`NODES`,
``football-ros`` dispatches its ROS commands from :func:`ros_commands`, and
``_early_signals`` recognises a node program from both.
"""

NODES = {
    # executable (= ros2 run football_ros NAME) -> module whose main(argv) runs the node
    'simulator': 'football_ros.nodes.simulator',
    'release': 'football_ros.nodes.release',
    'tracker': 'football_ros.nodes.tracker',
    'recorder': 'football_ros.nodes.recorder',
    'planner': 'football_ros.nodes.planner',
    'view': 'football_ros.nodes.view',
}
NODE_ALIASES = {'record': 'recorder'}
"""``football-ros record`` is the recorder node."""
ROS_TOOLS = {
    # football-ros command -> (module, function): ROS programs that are not nodes
    'demo': ('football_ros.tools.demo', 'main'),
    'echo': ('football_ros.nodes.console', 'echo'),
    'throw': ('football_ros.nodes.console', 'throw'),
}
CLI_SCRIPT = 'football-ros'


def ros_commands() -> dict[str, tuple[str, str]]:
    """``football-ros`` command -> (module, function) of every command that needs rclpy."""
    commands = {name: (module, 'main') for name, module in NODES.items()}
    commands.update({alias: (NODES[node], 'main') for alias, node in NODE_ALIASES.items()})
    commands.update(ROS_TOOLS)
    return commands


def node_command_names() -> tuple[str, ...]:
    """Return the ``football-ros`` commands that run a node (executable names, aliases)."""
    return (*NODES, *NODE_ALIASES)


def console_scripts() -> list[str]:
    """setup.py's console_scripts: ``football-ros`` and one executable per node."""
    return [f'{CLI_SCRIPT} = football_ros.cli:main'] + [
        f'{name} = {module}:main' for name, module in NODES.items()
    ]
