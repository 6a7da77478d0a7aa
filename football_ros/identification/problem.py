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
The fit's model of its data: unknowns -> whitened residuals, and their Jacobian.

The unknowns are, per flight (:class:`~.track.Track`), a block of ``N_BLOCK`` numbers, its
state at its first fix: position r [m], velocity v [m/s], the spin axis s by azimuth psi and
elevation theta [rad] in ``field``, and the transverse angular momentum h_perp = w_perp
[rad/s] along e_psi and e_theta (the unit vectors of growing psi and theta); and the values of
the freed quantities (:mod:`.coefficients`), shared by all flights. The rest of the model is
fixed (the ball's, the aero settings', the spin when not freed).

Residuals, whitened: each fix's position error over its sigma; each observed axis's error (the
observation taken along the model's axis, either sign) over the axis sigma, per component; and
per flight the release wobble's prior (:data:`N_PRIOR` terms): the axis's two components across
the air velocity over ``axis_prior`` and h_perp over ``rate_prior``, or over
:data:`HELD_RATE` where the rate is held (:attr:`FitSettings.release_rate`).

Why the rate is held where no axis is observed: h_perp sets the wobble's fast (nutation)
mode, which positions hardly see (its lift averages out within a cycle, a sub-millimetre
ripple) but for its mean drag, C_D2 sin^2 delta, never negative. Freed, each flight's rate
fits the noise: every pass gains drag, C_D0 loses it, and that bias stays while the interval
shrinks with more passes. Held, a wobble the positions cannot show adds its drag to C_D0; one
they do show is freed again (:func:`~.fit.fit`). The axis offset (the slow mode, seen through
the lift) stays free.

Sigmas: a fix's own where the track has one, else the given noise, else one sigma for all
such fixes, estimated (:meth:`Problem.estimate_noise`); the axes' likewise.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from . import coefficients as co
from .kernels import fly_rows, N_OUT
from .track import Track
from ..physics import model_params as mp
from ..physics.aero import AeroModel, resolve
from ..physics.presets import BallPreset
from ..physics.release import check_choice, MODELS, MOMENT_CURVES, RPM

N_BLOCK = 10
"""Unknowns per flight: r (3), v (3), psi, theta, h_perp (2)."""
B_R, B_V, B_PSI, B_THETA, B_W = 0, 3, 6, 7, 8
FD_BLOCK = np.array([1e-4, 1e-4, 1e-4, 1e-5, 1e-5, 1e-4, 1e-4])
"""Central-difference steps of v [m/s], psi, theta [rad] and h_perp [rad/s] (r is exact)."""
N_PRIOR = 4
"""Prior residuals per flight: the axis across the air velocity (2), h_perp (2)."""
START_AXIS_NOISE = math.radians(1.0)
"""Axis sigma [rad] the estimation of an unknown axis noise starts from."""
HELD_RATE = 1e-6
"""Prior sigma [rad/s] of a held h_perp: zero for any flight the data could show."""
MAX_STEP = 0.01
"""Longest RK4 step [s] (also at most 0.4 / |h1|, h1 the nutation's rate): against a 0.1 ms
flight, under 20 um and 0.03 deg off over a pass at 300-1200 rpm."""


@dataclass(frozen=True)
class FitSettings:
    """
    What to fit and how.

    ``ball`` (preset, overrides applied), ``model`` and ``moment`` as
    ``simulate`` takes them, ``aero`` the full model's fixed settings (None: the defaults),
    ``free`` names or aliases of :data:`~.coefficients.COEFFICIENTS` (None: the model's
    default), ``spin_rpm`` the release spin (None: the ball's nominal; the start when freed),
    ``noise`` [m] the sigma of fixes without their own and ``axis_noise`` [rad] (None:
    estimated), ``step`` the longest RK4 step [s] (None: from the spin), the wobble prior's
    ``axis_prior`` [rad] and ``rate_prior`` [rad/s], the ``release_rate`` (h_perp) of each
    flight: 'free' (under ``rate_prior``), 'held' at zero (the axis not turning at release) or
    'auto' (free for a flight with observed axes; for those without, held unless their
    positions show it: :func:`~.fit.fit`), whether to check the intervals against the
    ``profile`` likelihood, and the most Levenberg-Marquardt iterations.
    """

    ball: BallPreset
    model: str = 'full'
    moment: str = 'linear'
    aero: AeroModel | None = None
    free: tuple[str, ...] | None = None
    spin_rpm: float | None = None
    noise: float | None = None
    axis_noise: float | None = None
    step: float | None = None
    axis_prior: float = math.radians(10.0)
    rate_prior: float = 5.0
    release_rate: str = 'auto'
    profile: bool = True
    max_iterations: int = 60


def block_states(blocks: np.ndarray, spin: np.ndarray, ratio: float) -> np.ndarray:
    """
    Dynamics states (m, N_STATE) of flight unknowns ``blocks`` (m, N_BLOCK).

    ``spin`` (m,) [rad/s], ``ratio`` I_s/I_t; the attitude is yaw psi then pitch theta (body
    x = s), spin angle 0.
    """
    psi, theta = blocks[:, B_PSI], blocks[:, B_THETA]
    s, e_psi, e_theta = axis_frame(psi, theta)
    h1 = ratio * spin
    y = np.zeros((blocks.shape[0], mp.N_STATE))
    y[:, mp.R:mp.R + 6] = blocks[:, B_R:B_R + 6]
    a, b = np.sin(0.5 * psi), np.cos(0.5 * psi)
    c, d = -np.sin(0.5 * theta), np.cos(0.5 * theta)
    y[:, mp.Q], y[:, mp.Q + 1], y[:, mp.Q + 2], y[:, mp.Q + 3] = -a * c, b * c, d * a, b * d
    y[:, mp.H:mp.H + 3] = (
        h1[:, None] * s + blocks[:, B_W, None] * e_psi + blocks[:, B_W + 1, None] * e_theta
    )
    y[:, mp.H1] = h1
    return y


def axis_frame(psi: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, ...]:
    """Axis s, e_psi, e_theta (each (m, 3), ``field``) of azimuths and elevations [rad]."""
    cp, sp, ct, st = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta)
    s = np.column_stack([ct * cp, ct * sp, st])
    e_psi = np.column_stack([-sp, cp, np.zeros_like(sp)])
    e_theta = np.column_stack([-st * cp, -st * sp, ct])
    return s, e_psi, e_theta


@dataclass
class Linear:
    """Per flight: whitened residuals (n_f,) and their Jacobian (n_f, N_BLOCK + n_free)."""

    residuals: list
    jacobians: list

    @property
    def cost(self) -> float:
        """Chi-square."""
        return float(sum(r @ r for r in self.residuals))


class Problem:
    """The data, the whitening and the model of one fit; flies and differentiates."""

    def __init__(self, tracks: list[Track], model: FitSettings) -> None:
        check_choice('model', model.model, MODELS)
        check_choice('moment', model.moment, MOMENT_CURVES)
        self.ball, self.aero = resolve(model.ball, model.model, model.aero)
        self.names = co.parse_free(model.free, model.model, self.aero)
        self.n_free = len(self.names)
        self.spin_rpm = model.ball.spin_rpm if model.spin_rpm is None else float(model.spin_rpm)
        self.params = mp.make_params(self.ball, model.moment, self.aero)
        self.ratio = self.ball.inertia_ratio
        self.tracks = list(tracks)
        self.rel = [t.times - t.times[0] for t in tracks]
        self.axis_rows = [t.observed_axes for t in tracks]
        self.pos_sigma = [
            t.sigma if t.sigma is not None
            else np.full(t.times.size, math.nan if model.noise is None else float(model.noise))
            for t in tracks
        ]
        self.pos_estimated = [t.sigma is None and model.noise is None for t in tracks]
        self.axis_estimated = any(r.size for r in self.axis_rows) and model.axis_noise is None
        self.axis_sigma = START_AXIS_NOISE if model.axis_noise is None else model.axis_noise
        self.noise = first_noise(tracks)
        check_choice('release_rate', model.release_rate, co.RELEASE_RATES)
        self.release_rate = model.release_rate
        self.rate_free = np.array([
            model.release_rate == 'free' or (model.release_rate == 'auto' and bool(a.size))
            for a in self.axis_rows
        ])
        self.axis_prior, self.rate_prior = model.axis_prior, model.rate_prior
        h1 = abs(self.ratio * self.spin_rpm * RPM)
        self.step = model.step or min(MAX_STEP, 0.4 / max(h1, 1e-9))

    @property
    def n_data(self) -> int:
        """Freedoms of the data: 3 per fix, 2 per observed axis."""
        return sum(3 * r.size + 2 * a.size for r, a in zip(self.rel, self.axis_rows))

    @property
    def rate_sigma(self) -> np.ndarray:
        """Prior sigma (F,) [rad/s] of each flight's h_perp: ``rate_prior`` or held."""
        return np.where(self.rate_free, self.rate_prior, HELD_RATE)

    @property
    def n_held(self) -> int:
        """Unknowns held by their prior (h_perp of flights whose rate is held)."""
        return 2 * int(np.count_nonzero(~self.rate_free))

    def sigmas(self, f: int) -> np.ndarray:
        """Position sigma (K,) [m] of flight ``f`` now."""
        if self.pos_estimated[f]:
            return np.full(self.rel[f].size, self.noise)
        return self.pos_sigma[f]

    def fly(self, f: int, states: np.ndarray, params: np.ndarray) -> np.ndarray:
        """Positions and axes (m, K, N_OUT) of flight ``f`` from rows of states, parameters."""
        out = np.empty((states.shape[0], self.rel[f].size, N_OUT))
        fly_rows(states, params, self.rel[f], self.step, out)
        return out

    def evaluate(self, blocks: np.ndarray, values: np.ndarray) -> list[np.ndarray]:
        """
        Return the whitened residuals of rows of unknowns.

        ``blocks`` (F, m, N_BLOCK), ``values`` (m, n); one (m, n_f) array per flight: the
        fixes', the observed axes', the prior's.
        """
        n_f, m = blocks.shape[:2]
        flat = blocks.reshape(n_f * m, N_BLOCK)
        spin = np.tile(co.spin_of(self.names, values, self.spin_rpm), n_f)
        states = block_states(flat, spin, self.ratio).reshape(n_f, m, mp.N_STATE)
        params = co.apply(self.params, self.names, values, self.ball)
        prior = self.prior(flat, np.tile(params[:, mp.P_WIND:mp.P_WIND + 3], (n_f, 1)),
                           np.repeat(self.rate_sigma, m))
        prior = prior.reshape(n_f, m, N_PRIOR)
        out = []
        for f, track in enumerate(self.tracks):
            flown = self.fly(f, states[f], params)
            pos = (flown[:, :, :3] - track.positions) / self.sigmas(f)[:, None]
            parts = [pos.reshape(m, -1)]
            rows = self.axis_rows[f]
            if rows.size:
                model = flown[:, rows, 3:6]
                obs = track.axes[rows]
                sign = np.where(np.sum(model[0] * obs, axis=1) < 0.0, -1.0, 1.0)
                parts.append(((model - sign[:, None] * obs) / self.axis_sigma).reshape(m, -1))
            parts.append(prior[f])
            out.append(np.concatenate(parts, axis=1))
        return out

    def prior(self, blocks: np.ndarray, wind: np.ndarray, rate_sigma: np.ndarray) -> np.ndarray:
        """
        Return the wobble prior's whitened terms (m, N_PRIOR) of ``blocks`` in ``wind``.

        ``rate_sigma`` (m,) [rad/s] is each row's h_perp sigma.
        """
        u = blocks[:, B_V:B_V + 3] - wind
        e1 = u / np.linalg.norm(u, axis=1)[:, None]
        e2 = np.array([0.0, 0.0, 1.0]) - e1[:, 2:3] * e1
        e2 /= np.linalg.norm(e2, axis=1)[:, None]
        e3 = np.cross(e1, e2)
        s = axis_frame(blocks[:, B_PSI], blocks[:, B_THETA])[0]
        return np.column_stack([
            np.sum(s * e2, axis=1) / self.axis_prior,
            np.sum(s * e3, axis=1) / self.axis_prior,
            blocks[:, B_W:B_W + 2] / rate_sigma[:, None],
        ])

    def cost(self, blocks: np.ndarray, values: np.ndarray) -> float:
        """Chi-square of unknowns ``blocks`` (F, N_BLOCK), ``values`` (n,); inf if one fails."""
        with np.errstate(all='ignore'):  # a wild trial step overflows: refused, not warned
            res = self.evaluate(blocks[:, None, :], values[None])
            total = sum(float(r[0] @ r[0]) for r in res)
        return total if math.isfinite(total) else math.inf

    def linearise(self, blocks: np.ndarray, values: np.ndarray) -> Linear | None:
        """
        Return residuals and Jacobian at ``blocks`` (F, N_BLOCK), ``values`` (n,).

        None if a flight fails. Central differences (the wobble's near-flat directions need
        their accuracy), all rows of a flight in one kernel call; the position columns are
        exact (1/sigma on the fix's own axis: the flight does not depend on where it is).
        """
        steps = np.concatenate([FD_BLOCK, [co.COEFFICIENTS[n].fd_step for n in self.names]])
        half = steps.size
        moves = np.vstack([np.zeros(half), np.diag(steps), -np.diag(steps)])
        rows_b = np.repeat(blocks[:, None, :], moves.shape[0], axis=1)
        rows_b[:, :, B_V:] += moves[:, :FD_BLOCK.size]
        rows_v = values[None] + moves[:, FD_BLOCK.size:]
        lin = Linear([], [])
        for f, res in enumerate(self.evaluate(rows_b, rows_v)):
            if not np.all(np.isfinite(res)):
                return None
            jac = np.zeros((res.shape[1], N_BLOCK + self.n_free))
            jac[:, B_V:] = ((res[1:1 + half] - res[1 + half:]) / (2.0 * steps[:, None])).T
            k = self.rel[f].size
            inv = 1.0 / self.sigmas(f)
            for j in range(3):
                jac[j:3 * k:3, B_R + j] = inv
            lin.residuals.append(res[0])
            lin.jacobians.append(jac)
        return lin

    def estimate_noise(self, lin: Linear, n_params: int) -> float:
        """
        Set the estimated sigmas from the residuals at a fit; return the largest change.

        Sum of squares over the data's freedoms less ``n_params``; the change is relative.
        """
        keep = max(1.0 - n_params / max(self.n_data, 1), 1e-3)
        change = 0.0
        if any(self.pos_estimated):
            ss = n = 0.0
            for f, r in enumerate(lin.residuals):
                if self.pos_estimated[f]:
                    k = 3 * self.rel[f].size
                    ss += float(r[:k] @ r[:k]) * self.noise**2
                    n += k
            new = max(math.sqrt(ss / (n * keep)), 1e-9)
            change, self.noise = abs(new / self.noise - 1.0), new
        if self.axis_estimated:
            ss = n = 0.0
            for f, r in enumerate(lin.residuals):
                a = r[3 * self.rel[f].size:r.size - N_PRIOR]
                ss += float(a @ a) * self.axis_sigma**2
                n += 2 * self.axis_rows[f].size
            new = max(math.sqrt(ss / (n * keep)), 1e-9)
            change, self.axis_sigma = max(change, abs(new / self.axis_sigma - 1.0)), new
        return change

    def start(self, values: np.ndarray) -> np.ndarray:
        """
        Return the start blocks (F, N_BLOCK).

        r and v from a cubic through each flight's fixes, the axis along v (or the first
        observed axis), no transverse rate.
        """
        blocks = np.zeros((len(self.tracks), N_BLOCK))
        for f, track in enumerate(self.tracks):
            t = self.rel[f]
            coef = np.polynomial.polynomial.polyfit(t / t[-1], track.positions, 3)
            v0 = coef[1] / t[-1]
            axis = v0 / max(np.linalg.norm(v0), 1e-9)
            rows = self.axis_rows[f]
            if rows.size:
                seen = track.axes[rows[0]]
                axis = seen if seen @ axis >= 0.0 else -seen
            blocks[f, B_R:B_R + 3], blocks[f, B_V:B_V + 3] = coef[0], v0
            blocks[f, B_PSI] = math.atan2(axis[1], axis[0])
            blocks[f, B_THETA] = math.asin(max(-1.0, min(1.0, axis[2])))
        return blocks


def first_noise(tracks: list[Track]) -> float:
    """
    Return the position sigma [m] the estimation starts from.

    From third differences of the fixes: a smooth flight's are far below the noise's, whose
    variance they multiply by 20.
    """
    diffs = np.concatenate([np.diff(t.positions, 3, axis=0).ravel() for t in tracks])
    return max(math.sqrt(np.mean(diffs**2) / 20.0), 1e-4)
