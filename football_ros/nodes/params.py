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

"""Parameter declaration with descriptors (description, ranges): one helper for every node."""

from __future__ import annotations

from dataclasses import dataclass

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter


def declare(
    node: Node,
    name: str,
    default,
    description: str,
    limits: tuple[float, float] | None = None,
    read_only: bool = False,
):
    """
    Declare ``name`` with a descriptor; numeric ``limits`` become an enforced range.

    Returns the value in force (the default or a --ros-args override, which rclpy checks
    against the range before the node starts). An integer override of a float parameter
    (``publish_rate:=1000``) is taken as that float.
    """
    override = node._parameter_overrides.get(name)
    if (
        isinstance(default, float)
        and override is not None
        and override.type_ == Parameter.Type.INTEGER
    ):
        node._parameter_overrides[name] = Parameter(
            name, Parameter.Type.DOUBLE, float(override.value)
        )
    descriptor = ParameterDescriptor(description=description, read_only=read_only)
    if limits is not None:
        lo, hi = limits
        if isinstance(default, bool):
            raise TypeError('a bool parameter takes no range')
        if isinstance(default, int):
            descriptor.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=1)]
        else:
            descriptor.floating_point_range = [
                FloatingPointRange(from_value=float(lo), to_value=float(hi), step=0.0)
            ]
    return node.declare_parameter(name, default, descriptor).value


@dataclass(frozen=True)
class ParamSpec:
    """One parameter of a node: the single source for its declaration and its ``--help`` line."""

    name: str
    default: object
    description: str
    limits: tuple[float, float] | None = None

    def declare(self, node: Node):
        return declare(node, self.name, self.default, self.description, self.limits)

    def help_line(self) -> str:
        limits = f' [{self.limits[0]:g} .. {self.limits[1]:g}]' if self.limits else ''
        return f'  {self.name} (default {self.default!r}{limits}): {self.description}'
