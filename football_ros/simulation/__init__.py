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
The whole simulation without ROS: the world of balls, its clock, play / pause / stop and steps.

:class:`Simulation` (core.py) is what the simulator node serves; :class:`World` (world.py)
keeps every ball's numbers in arrays that one compiled pass (kernel.py) advances; names.py
matches name filters in linear time. Layer: above physics, below the nodes.
"""

from .core import EntityValues, Frame, PAUSED, PLAYING, Simulation, STOPPED  # noqa: F401
from .world import (  # noqa: F401
    DEFAULT_ENTITY,
    Entity,
    EntityError,
    FlightRun,
    World,
)
