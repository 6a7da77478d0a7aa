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
Pure physics of a spinning football (no ROS imports). Frames and units: docs/physics.md.

The numba-compiled parts (:mod:`.flight`, :mod:`.dynamics`, :mod:`.batch`) are imported on
first use, so that commands which only need the linear theory start without numba.
"""

from .linear_theory import linear_modes, LinearModes
from .presets import BallPreset, get_preset, PRESETS
from .release import InitialState, Release, ReleaseError

__all__ = [
    'CSV_HEADER',
    'Flight',
    'Trajectory',
    'LinearModes',
    'linear_modes',
    'PRESETS',
    'BallPreset',
    'get_preset',
    'InitialState',
    'Release',
    'ReleaseError',
    'compile_ahead',
]

_LAZY = {
    'CSV_HEADER': 'flight',
    'Flight': 'flight',
    'Trajectory': 'flight',
    'compile_ahead': 'precompile',
}


def __getattr__(name: str):
    """Import the numba-backed names on first use (PEP 562)."""
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f'.{_LAZY[name]}', __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
