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

"""throttled: one line per call site and logger per period, decided before rclpy is called."""

import os
from pathlib import Path
import subprocess
import sys

from football_ros.nodes.logs import throttled

REPO = Path(__file__).resolve().parent.parent


class Recorder:

    def __init__(self, name: str) -> None:
        self.name = name
        self.lines = []

    def warning(self, text: str) -> None:
        self.lines.append(('warning', text))

    def info(self, text: str) -> None:
        self.lines.append(('info', text))


def test_one_line_per_call_site_and_logger_per_period():
    a, b = Recorder('a'), Recorder('b')
    printed = [throttled(a, 'warning', f'first {k}', 3600.0) for k in range(100)]
    assert printed == [True] + [False] * 99  # one call site: its first line only
    for k in range(5):
        throttled(a, 'info', f'second {k}', 3600.0)  # another call site: its own line
        throttled(b, 'info', f'other logger {k}', 3600.0)
    assert a.lines == [('warning', 'first 0'), ('info', 'second 0')]
    assert b.lines == [('info', 'other logger 0')]
    assert [throttled(a, 'info', f'always {k}', 0.0) for k in range(3)] == [True] * 3
    assert a.lines[-3:] == [('info', f'always {k}') for k in range(3)]


def test_a_printed_line_names_the_nodes_call_site_not_this_helper():
    code = (
        'import rclpy\n'
        'rclpy.init()\n'
        'from football_ros.nodes.logs import throttled\n'
        "node = rclpy.create_node('logs_test')\n"
        'def the_call_site():\n'
        "    throttled(node.get_logger(), 'warning', 'hello', 1.0)\n"
        'the_call_site()\n'
    )
    env = dict(os.environ, PYTHONPATH=str(REPO),  # the suite's own ROS_DOMAIN_ID (conftest)
               RCUTILS_CONSOLE_OUTPUT_FORMAT='{severity} {function_name} {message}')
    out = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert 'WARN the_call_site hello' in out.stderr + out.stdout
