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
The simulator's ROS-free half: a world of named balls, each a flight run (no ROS imports).

Layer: above physics (it imports only :mod:`football_ros.physics`), below the nodes
(:mod:`football_ros.nodes.simulator` paces, publishes and serves it).
"""

from .world import (  # noqa: F401
    DEFAULT_ENTITY,
    Entity,
    EntityError,
    FlightRun,
    World,
)
