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
Throw planning (no ROS): from a target in ``field`` to the release that gets there.

:func:`plan` shoots on the package's own flight (:class:`football_ros.physics.Flight`, the
simulator's step) and gives the least-wobble release attitude; :func:`hit_probability` flies
the plan under release noise with the batch kernel.
"""

from .planner import (
    equilibrium_attitude,
    OBJECTIVES,
    Plan,
    plan,
    PlanError,
    Receiver,
    wobble_of,
)
from .robustness import (
    arcs_summary,
    compare_arcs,
    DEFAULT_SIGMAS,
    hit_probability,
    HitEstimate,
    wilson,
)

__all__ = [
    'arcs_summary',
    'DEFAULT_SIGMAS',
    'HitEstimate',
    'OBJECTIVES',
    'Plan',
    'PlanError',
    'Receiver',
    'compare_arcs',
    'equilibrium_attitude',
    'hit_probability',
    'plan',
    'wilson',
    'wobble_of',
]
