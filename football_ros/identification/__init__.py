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
Coefficients from measured flights (no ROS): the inverse of ``simulate``.

:mod:`.track` checks a measured flight, :mod:`.coefficients` lists what may be freed,
:mod:`.kernels` flies the fit's states, :mod:`.problem` turns unknowns into residuals,
:mod:`.solver` minimises them (Levenberg-Marquardt) and profiles, :mod:`.uncertainty` turns
the information into intervals and identifiability, :mod:`.fit` drives and reports. The
compiled parts load on first use (a command's options need only the table of coefficients).
"""

__all__ = [
    'COEFFICIENTS',
    'CoefficientFit',
    'fit',
    'FitError',
    'FitResult',
    'FitSettings',
    'FlightFit',
    'Track',
]

_LAZY = {
    'COEFFICIENTS': 'coefficients',
    'CoefficientFit': 'fit',
    'fit': 'fit',
    'FitError': 'solver',
    'FitResult': 'fit',
    'FitSettings': 'problem',
    'FlightFit': 'fit',
    'Track': 'track',
}


def __getattr__(name: str):
    """Import the names on first use (PEP 562): numba loads only when a fit runs."""
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f'.{_LAZY[name]}', __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
