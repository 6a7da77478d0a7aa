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
Start-up and clean shutdown shared by every node (the Jazzy demo_nodes_py pattern).

Ctrl-C (SIGINT) and SIGTERM end the spin without a traceback; the node's ``close()`` (if any)
runs before the node is destroyed, so threads stop and files are flushed.
"""

from __future__ import annotations

import sys
from typing import Callable, Sequence

import rclpy
from rclpy._rclpy_pybind11 import RCLError
from rclpy.exceptions import InvalidParameterTypeException, ParameterException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


def run_node(factory: Callable[[], Node], argv: Sequence[str] | None, program: str) -> int:
    """Init rclpy with ``argv`` (ROS arguments included), spin the node, shut down cleanly."""
    args = [program, *(sys.argv[1:] if argv is None else argv)]
    rclpy.init(args=args)
    node = None
    code = 0
    try:
        try:
            node = factory()
        except (ParameterException, InvalidParameterTypeException, ValueError) as exc:
            # A start-up error (a parameter override out of range, ...): one clear line.
            print(f'{program}: error: {exc}', file=sys.stderr)
            return 2
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except RCLError:
        # A signal can shut the context down between two executor iterations; rclpy then
        # fails to build the next wait set instead of raising ExternalShutdownException.
        if rclpy.ok():
            raise
    finally:
        if node is not None:
            close = getattr(node, 'close', None)
            if close is not None:
                close()
            node.destroy_node()
        rclpy.try_shutdown()
    return code
