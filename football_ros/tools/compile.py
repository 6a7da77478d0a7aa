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
``football-ros compile``: load (or compile, first time) every numba kernel a node or command runs.

:data:`STEPS` is the one list: the physics' steps (:mod:`football_ros.physics.precompile`), then
the simulator's many-ball world, the tracker, the planner and the Monte Carlo CSV writer, each
through its own warm-up. :data:`PLACES` are the packages and modules whose kernels count; after
:func:`compile_all` on a cold cache none of them is left uncompiled, and the nodes' warm-ups
then compile nothing (test_compile checks both).
"""

from __future__ import annotations

from typing import Callable

from . import fastcsv
from .. import estimation, identification, physics, planning, simulation
from ..estimation.tracker import warm_up as tracker_warm_up
from ..identification.kernels import warm_up as fit_warm_up
from ..physics.precompile import compile_ahead, CompileStep, STEPS as PHYSICS_STEPS
from ..planning.planner import warm_up as planner_warm_up
from ..simulation.kernel import warm_up as world_warm_up

PLACES = (physics, simulation, estimation, planning, identification, fastcsv)
"""Every package or module that holds numba kernels."""

STEPS: tuple[tuple[str, Callable[[], object]], ...] = PHYSICS_STEPS + (
    ('many-ball kernel (simulator world)', world_warm_up),
    ('tracker (filter, batch fit, predictions)', tracker_warm_up),
    ('planner (one short plan)', planner_warm_up),
    ('CSV writer (Monte Carlo)', fastcsv.warm_up),
    ('coefficient fit (football-ros fit)', fit_warm_up),
)


def compile_all(progress: Callable[[str], None] | None = None) -> list[CompileStep]:
    """Run :data:`STEPS`; one :class:`CompileStep` each (``progress`` as in compile_ahead)."""
    return compile_ahead(progress, STEPS, PLACES)
