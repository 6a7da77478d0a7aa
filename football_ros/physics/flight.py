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
A flight: initial state + ball + model, integrated headless or paced in real time.

Everything is in ``field`` and SI. :class:`Flight` owns the state vector of
:mod:`football_ros.physics.dynamics`; :class:`Trajectory` turns sampled state vectors into the
quantities users read (pose, axis, alpha/beta against the air, and the linear-theory
predictions: frozen at release and quasi-steady along the flight).
"""

from __future__ import annotations

import csv
import dataclasses
from dataclasses import dataclass
from functools import cached_property
import math
from pathlib import Path

import numpy as np

from . import dynamics as dyn
from .aero import AeroModel
from .linear_theory import LinearModes, quasi_steady_components
from .modes import flown_model, flown_modes
from .presets import BallPreset
from .quasi_steady import QuasiSteadyTracker
from .release import check_choice, InitialState, MODELS, MOMENT_CURVES, Release
from .step_stability import check_flyable

DEFAULT_STEP = 1e-3
"""Default integration step [s]: RK4 error on alpha/beta stays below 1e-6 rad over a pass."""

CSV_BASE_HEADER = (
    't',
    'x',
    'y',
    'z',
    'vx',
    'vy',
    'vz',
    'qx',
    'qy',
    'qz',
    'qw',
    'sx',
    'sy',
    'sz',
    'alpha',
    'beta',
    'alpha_linear',
    'beta_linear',
)
"""The 18 columns every simulate CSV starts with, in this order (a contract: never reordered)."""
CSV_HEADER = CSV_BASE_HEADER + ('delta', 'alpha_quasi_steady', 'beta_quasi_steady', 'spin')
"""Columns written by :meth:`Trajectory.write_csv`: the base 18, then (appended) the total angle
delta [rad], the quasi-steady linear theory's alpha, beta [rad] and the spin p [rad/s]."""


@dataclass(frozen=True)
class Trajectory:
    """
    Sampled flight.

    ``times`` (N,) [s] since release, ``states`` (N, N_STATE) state vectors; ``params`` the
    kernel parameters flown (None: the paper's, no wind).
    """

    times: np.ndarray
    states: np.ndarray
    landed: bool
    ball: BallPreset
    modes: LinearModes
    params: np.ndarray | None = None

    @property
    def wind(self) -> np.ndarray:
        """Wind [m/s] in ``field`` (zeros without)."""
        if self.params is None:
            return np.zeros(3)
        return self.params[dyn.P_WIND:dyn.P_WIND + 3].copy()

    @property
    def air_velocities(self) -> np.ndarray:
        """(N, 3) air-relative velocity u = v - wind [m/s] in ``field``."""
        return self.velocities - self.wind

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) [m] in ``field``."""
        return self.states[:, dyn.R:dyn.R + 3]

    @property
    def velocities(self) -> np.ndarray:
        """(N, 3) [m/s] in ``field``."""
        return self.states[:, dyn.V:dyn.V + 3]

    @cached_property
    def _described(self) -> np.ndarray:
        params = self.params if self.params is not None else dyn.make_params(self.ball)
        return dyn.describe(self.states, params)  # I_t/I_s and the wind

    @property
    def axes(self) -> np.ndarray:
        """(N, 3) unit spin axis in ``field``."""
        return self._described[:, dyn.D_AXIS:dyn.D_AXIS + 3]

    @property
    def orientations(self) -> np.ndarray:
        """(N, 4) ball orientation (x, y, z, w), body x = axis, spin angle included."""
        return self._described[:, dyn.D_ORIENT:dyn.D_ORIENT + 4]

    @property
    def angular_velocities(self) -> np.ndarray:
        """(N, 3) ball angular velocity [rad/s] in ``field``: w = h - h1 s + p s."""
        return self._described[:, dyn.D_OMEGA:dyn.D_OMEGA + 3]

    @property
    def spin_momentum(self) -> np.ndarray:
        """(N,) h.s [rad/s], computed from h and s (not the stored h1)."""
        return np.sum(self.states[:, dyn.H:dyn.H + 3] * self.axes, axis=-1)

    @property
    def aero_angles(self) -> np.ndarray:
        """(N, 3) alpha, beta, delta [rad] of the integrated flight, against the air."""
        return self._described[:, dyn.D_ALPHA:dyn.D_DELTA + 1]

    @property
    def aero_angles_linear(self) -> np.ndarray:
        """(N, 2) alpha, beta [rad] of the linear theory, V and Phi frozen at release."""
        return np.stack(self.modes.aero_angles(self.times), axis=-1)

    @property
    def spin(self) -> np.ndarray:
        """(N,) spin p = (I_t/I_s) h1 [rad/s] about the axis."""
        return self.states[:, dyn.H1] / self.ball.inertia_ratio

    @cached_property
    def axis_components_quasi_steady(self) -> np.ndarray:
        """
        Return (N,) complex x = s2 + i s3 of the quasi-steady linear theory.

        Local U, Phi, h1, and the flown model's lift, damping and Magnus terms.
        """
        params = dyn.make_params(self.ball) if self.params is None else self.params
        return quasi_steady_components(
            self.modes, params, self.times, self.air_velocities, self.states[:, dyn.H1]
        )

    @property
    def aero_angles_quasi_steady(self) -> np.ndarray:
        """
        (N, 2) alpha, beta [rad] of the quasi-steady linear theory.

        M_alpha(U), w_V, s3p and h1 local, phases integrated along the flight
        (docs/physics.md).
        """
        from .linear_theory import angles_from_components

        return np.stack(angles_from_components(self.axis_components_quasi_steady), axis=-1)

    def table(self) -> np.ndarray:
        """(N, len(CSV_HEADER)) rows in the order of :data:`CSV_HEADER`."""
        return np.column_stack(
            [
                self.times,
                self.positions,
                self.velocities,
                self.orientations,
                self.axes,
                self.aero_angles[:, :2],
                self.aero_angles_linear,
                self.aero_angles[:, 2],
                self.aero_angles_quasi_steady,
                self.spin,
            ]
        )

    def write_csv(self, path: str | Path) -> None:
        """Write :meth:`table` with :data:`CSV_HEADER` (full float precision)."""
        with open(path, 'w', newline='') as handle:
            writer = csv.writer(handle)
            writer.writerow(CSV_HEADER)
            writer.writerows([[repr(float(v)) for v in row] for row in self.table()])


class Flight:
    """
    One ball in flight: build from a :class:`Release` or an :class:`InitialState`.

    ``step`` is the fixed integration step [s]; sampling never changes the trajectory.
    """

    def __init__(
        self,
        ball: BallPreset,
        initial: InitialState,
        model: str = 'paper',
        moment: str = 'linear',
        step: float = DEFAULT_STEP,
        aero: AeroModel | None = None,
    ) -> None:
        check_choice('model', model, MODELS)
        check_choice('moment', moment, MOMENT_CURVES)
        if not (0.0 < step <= 0.05):
            raise ValueError(f'integration step must be in (0, 0.05] s, got {step}')
        ball, self.aero, self.params = flown_model(ball, model, moment, aero)
        self.ball, self.initial, self.model, self.moment, self.step = (
            ball,
            initial,
            model,
            moment,
            step,
        )
        self.wind = self.params[dyn.P_WIND:dyn.P_WIND + 3].copy()
        check_flyable(self.params, initial, step)  # one check for every entry point
        self.modes = flown_modes(ball, initial, self.params)
        y0 = np.zeros(dyn.N_STATE)
        y0[dyn.R:dyn.R + 3] = initial.position
        y0[dyn.V:dyn.V + 3] = initial.velocity
        y0[dyn.Q:dyn.Q + 4] = initial.attitude
        y0[dyn.H:dyn.H + 3] = initial.modified_momentum(ball)
        y0[dyn.H1] = ball.inertia_ratio * initial.spin
        self.y0 = y0
        self.rewind()

    @classmethod
    def from_release(cls, release: Release, step: float = DEFAULT_STEP) -> 'Flight':
        return cls(
            release.preset(),
            release.initial_state(),
            release.model,
            release.moment,
            step,
            release.aero_model(),
        )

    # --- headless ---------------------------------------------------------------------------
    def simulate(
        self, rate: float = 100.0, duration: float = 10.0, ground: float = 0.0
    ) -> Trajectory:
        """
        Return samples at multiples of 1/``rate`` [Hz] from t = 0.

        Until ``duration`` [s] or the landing on z = ``ground`` (then the last sample is
        the landing itself).
        """
        times, states, landed = dyn.propagate(
            self.y0, self.step, self.params, 1.0 / rate, duration, ground
        )
        return Trajectory(times, states, landed, self.ball, self.modes, self.params)

    # --- real time --------------------------------------------------------------------------
    def rewind(self) -> None:
        """Back to the release (t = 0)."""
        self._y = self.y0.copy()
        self._steps = 0
        self.landing_time: float | None = None
        self._landing_state: np.ndarray | None = None
        self._quasi_steady = QuasiSteadyTracker(
            self.modes, self.params, self.initial.velocity - self.wind
        )

    def state_at(self, t: float, ground: float = 0.0) -> np.ndarray:
        """
        State vector at time ``t`` [s] after release (t never decreasing between calls).

        Whole steps are committed, the remainder is a partial step (one compiled march,
        :func:`~football_ros.physics.dynamics.march`). After the landing the landing state is
        returned; ``landing_time`` is then set.
        """
        if self._landing_state is not None:
            return self._landing_state
        nxt = np.empty(dyn.N_STATE)
        work = np.empty((5, dyn.N_STATE))
        target = int(math.floor(t / self.step + 1e-9))
        self._steps, crossed = dyn.march(
            self._y, self._steps, target, self.step, self.params, ground, nxt, work
        )
        rest = self.step if crossed else t - self._steps * self.step
        state = np.empty(dyn.N_STATE)
        tau = dyn.finish(self._y, rest, self.params, ground, crossed, state, work)
        if not math.isnan(tau):
            self.landing_time = self._steps * self.step + tau
            self._landing_state = state
        return state

    def theory_angles(self, t: float, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Alpha, beta [rad] of the linear theory frozen at release and of the quasi-steady one.

        At ``t`` [s] after release, ``state`` the flight's state then (times never decreasing
        between calls: the quasi-steady integrals advance with them).
        """
        return self.linear_angles(t), self.quasi_steady_angles(t, state)

    def linear_angles(self, t: float) -> np.ndarray:
        """Alpha, beta [rad] of the linear theory frozen at release, ``t`` [s] after it."""
        alpha, beta = self.modes.aero_angles(t)
        return np.array([float(alpha), float(beta)])

    def quasi_steady_angles(self, t: float, state: np.ndarray) -> np.ndarray:
        """
        Alpha, beta [rad] of the quasi-steady theory at ``t`` [s], ``state`` the flight's then.

        Its integrals advance with ``t`` (never decreasing between calls), so a flight shown
        frame by frame calls this every frame, whoever reads the angles.
        """
        return self._quasi_steady.update(
            t, state[dyn.V:dyn.V + 3] - self.wind, float(state[dyn.H1])
        )

    def sample(self, t: float, ground: float = 0.0) -> 'BallSample':
        """Return the ball at ``t`` [s] after release (or at its landing, once landed)."""
        state = self.state_at(t, ground)
        landed = self.landing_time is not None
        t_state = self.landing_time if landed else t
        d = dyn.describe(state[None, :], self.params)[0]
        linear, quasi = self.theory_angles(t_state, state)
        return BallSample(
            t=t_state,
            position=state[dyn.R:dyn.R + 3].copy(),
            velocity=state[dyn.V:dyn.V + 3].copy(),
            orientation=d[dyn.D_ORIENT:dyn.D_ORIENT + 4],
            axis=d[dyn.D_AXIS:dyn.D_AXIS + 3],
            angular_velocity=d[dyn.D_OMEGA:dyn.D_OMEGA + 3],
            aero_angles=d[dyn.D_ALPHA:dyn.D_DELTA + 1],
            aero_angles_linear=linear,
            landed=landed,
            aero_angles_quasi_steady=quasi,
        )


@dataclass(frozen=True)
class BallSample:
    """
    One instant of a flight, in ``field``.

    t [s] since release, position [m], velocity [m/s], orientation (x, y, z, w; body x = axis),
    axis (unit), angular_velocity [rad/s], aero_angles (alpha, beta, delta) [rad] against the
    air (v - wind), aero_angles_linear (alpha, beta) [rad] of the linear theory frozen at
    release, aero_angles_quasi_steady (alpha, beta) [rad] of the quasi-steady linear theory
    (NaN once an unstable ball's theory overflows).
    """

    t: float
    position: np.ndarray
    velocity: np.ndarray
    orientation: np.ndarray
    axis: np.ndarray
    angular_velocity: np.ndarray
    aero_angles: np.ndarray
    aero_angles_linear: np.ndarray
    landed: bool
    aero_angles_quasi_steady: np.ndarray = dataclasses.field(
        default_factory=lambda: np.full(2, np.nan)
    )


def flight_summary(times: np.ndarray, positions: np.ndarray, landed: bool) -> dict[str, float]:
    """
    Time_of_flight [s], range [m] (horizontal, from the release), apex height [m].

    Of samples ``times`` (N,) and ``positions`` (N, 3) in ``field``; NaN time and range when
    the flight had not landed.
    """
    horizontal = positions[-1, :2] - positions[0, :2]
    return {
        'time_of_flight': float(times[-1]) if landed else math.nan,
        'range': float(np.hypot(*horizontal)) if landed else math.nan,
        'apex_height': float(np.max(positions[:, 2])),
    }
