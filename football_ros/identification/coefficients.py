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
The quantities a fit may free: the shared coefficients, the spin and a constant wind.

:data:`COEFFICIENTS` is the one table of them: unit, the model they act in, their physical
range (what a ball could plausibly have: an interval wider than it says the data cannot tell)
and the finite-difference step of the Jacobian. :func:`start_values` reads each one's value
from the ball, the aero settings and the spin the fit starts from; :func:`apply` writes values
into kernel parameter rows (:func:`football_ros.physics.model_params.make_params` layout).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics import model_params as mp
from ..physics.aero import AeroModel
from ..physics.presets import BallPreset
from ..physics.release import RPM


@dataclass(frozen=True)
class Coefficient:
    """
    One quantity a fit may free.

    ``unit`` as printed; ``models`` those it acts in; ``physical`` (lo, hi) its physical range;
    ``fd_step`` the central-difference step of the Jacobian (in its unit); ``switch`` the
    :class:`AeroModel` switch that must be on for it to act (None: always acts).
    """

    name: str
    unit: str
    models: tuple[str, ...]
    physical: tuple[float, float]
    fd_step: float
    switch: str | None
    text: str


FULL = ('full',)
BOTH = ('paper', 'full')
COEFFICIENTS: dict[str, Coefficient] = {
    c.name: c
    for c in (
        Coefficient('c_d0', '', FULL, (0.0, 0.25), 1e-5, 'drag', 'drag end-on, C_D0'),
        Coefficient('c_d2', '', FULL, (0.0, 1.0), 1e-5, 'drag', 'drag rise, C_D2 sin^2 delta'),
        Coefficient('c_l_alpha', '1/rad', FULL, (0.0, 1.0), 1e-5, 'lift', 'lift slope'),
        Coefficient('c_n_p_alpha', '1/rad', FULL, (-0.5, 0.5), 1e-5, 'magnus', 'Magnus force'),
        Coefficient('c_m_alpha', '1/rad', BOTH, (0.0, 1.0), 1e-5, None, 'overturning moment'),
        Coefficient('c_m_q', '', FULL, (-20.0, 0.0), 1e-4, 'pitch_damping', 'pitch damping'),
        Coefficient('c_l_p', '', FULL, (-0.1, 0.0), 1e-6, 'spin_damping', 'spin damping'),
        Coefficient('spin_rpm', 'rpm', BOTH, (-1500.0, 1500.0), 1e-2, None, 'release spin'),
        Coefficient('wind_x', 'm/s', FULL, (-20.0, 20.0), 1e-4, None, 'wind along x'),
        Coefficient('wind_y', 'm/s', FULL, (-20.0, 20.0), 1e-4, None, 'wind along y'),
    )
}
"""Every quantity a fit may free, by name (the order of reports). Physical ranges: C_D0 from
end-on drag of balls and bodies of revolution (football 0.05-0.06, rugby balls and other
spheroids up to about 0.2); C_D2 up to a cylinder's broadside 1.2 less end-on; C_Lalpha of
slender bodies (football 0.4); C_Npalpha the span of McCoy's spin-stabilised projectiles;
C_Malpha from the rugby ball's 0.147 and the football's 0.33 with room; C_Mq and C_lp wide
(no ball data); the spin of passes and kicks; winds a game is played in."""

ALIASES = {'spin': ('spin_rpm',), 'wind': ('wind_x', 'wind_y')}
"""Names ``--free`` also takes."""

RELEASE_RATES = ('auto', 'free', 'held')
"""How a fit treats each flight's transverse angular velocity at release
(:attr:`~.problem.FitSettings.release_rate`)."""

DEFAULT_FREE = {'full': ('c_d0', 'c_l_alpha'), 'paper': ('c_m_alpha',)}
"""What a fit frees when the user does not say."""


def parse_free(names, model: str, aero: AeroModel | None) -> tuple[str, ...]:
    """
    Return the freed names in :data:`COEFFICIENTS` order; ValueError naming a bad one.

    ``names`` an iterable of names or aliases (None: :data:`DEFAULT_FREE`); each must act in
    ``model`` and, in the full model, have its ``aero`` switch on.
    """
    if names is None:
        names = DEFAULT_FREE[model]
    chosen = set()
    for raw in names:
        name = str(raw).strip()
        if not name:
            continue
        expanded = ALIASES.get(name, (name,))
        for key in expanded:
            if key not in COEFFICIENTS:
                raise ValueError(
                    f"unknown coefficient '{name[:40]}' (known: "
                    f'{", ".join(list(COEFFICIENTS) + list(ALIASES))})'
                )
            coefficient = COEFFICIENTS[key]
            if model not in coefficient.models:
                raise ValueError(f"'{key}' does not act in the {model} model (--model full)")
            if aero is not None and coefficient.switch and not getattr(aero, coefficient.switch):
                raise ValueError(f"'{key}' is switched off ({coefficient.switch}=false)")
            chosen.add(key)
    if not chosen:
        raise ValueError('nothing to fit: name at least one coefficient to free')
    return tuple(name for name in COEFFICIENTS if name in chosen)


def start_values(
    names: tuple[str, ...], ball: BallPreset, aero: AeroModel | None, spin_rpm: float
) -> np.ndarray:
    """Values of ``names`` the fit starts from (and keeps, for those not freed)."""
    aero = aero or AeroModel()
    values = {
        'c_m_alpha': ball.c_m_alpha,
        'spin_rpm': spin_rpm,
        'wind_x': aero.wind[0],
        'wind_y': aero.wind[1],
    }
    return np.array([values[n] if n in values else getattr(aero, n) for n in names])


_SLOT = {
    'c_d0': mp.P_CD0,
    'c_d2': mp.P_CD2,
    'c_l_alpha': mp.P_CLA,
    'c_n_p_alpha': mp.P_CNPA,
    'c_m_q': mp.P_CMQ,
    'c_l_p': mp.P_CLP,
    'wind_x': mp.P_WIND,
    'wind_y': mp.P_WIND + 1,
}


def apply(
    params: np.ndarray, names: tuple[str, ...], values: np.ndarray, ball: BallPreset
) -> np.ndarray:
    """
    Kernel parameter rows (m, N_PARAM): ``params`` (N_PARAM,) with ``values`` (m, n) written.

    ``spin_rpm`` is a state, not a parameter: it is skipped here (:func:`spin_of`).
    """
    values = np.atleast_2d(values)
    rows = np.repeat(params[None, :], values.shape[0], axis=0)
    per_c_m_alpha = ball.moment_coefficient() / ball.c_m_alpha
    for j, name in enumerate(names):
        if name == 'c_m_alpha':
            rows[:, mp.P_MOMENT_K] = per_c_m_alpha * values[:, j]
        elif name in _SLOT:
            rows[:, _SLOT[name]] = values[:, j]
    return rows


def spin_of(names: tuple[str, ...], values: np.ndarray, spin_rpm: float) -> np.ndarray:
    """Spin p [rad/s] of each row of ``values`` (m, n): its spin_rpm if freed, else the fixed."""
    values = np.atleast_2d(values)
    if 'spin_rpm' in names:
        return values[:, names.index('spin_rpm')] * RPM
    return np.full(values.shape[0], spin_rpm * RPM)
