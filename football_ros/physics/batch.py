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
Many flights at once: arrays of releases in, arrays of landings and wobble statistics out.

The kernel integrates each ball with the forces and moments of
:func:`football_ros.physics.dynamics.loads` (the same physics as the real-time kernel) on the
lean state (r, v, s, h, h1), with the 8th-order Dormand-Prince weights (:mod:`.dop853`) at a
fixed step, |s| = 1 and h.s = h1 restored after every step, balls spread over the cores
with numba ``prange`` (blocks of balls, the ball index innermost). The default step follows the
fastest rate of each ball's motion (:func:`fastest_rates`, ``STEP_PER_RADIAN``): 29 ms for the
nominal spiral, shorter for strong damping. The maxima of |alpha|, |beta| and delta are taken at
the steps. The landing is located inside its step on the cubic Hermite interpolant of z.

The stage sums are written out with the tableau's non-zero coefficients as literals
(:func:`_block_step_source`: no loop over coefficients, no zero weights, no position stages) and
the kernel is compiled with fast-math contract, arcp, nsz and reassoc (FMA, one division per
ball), but not nnan/ninf, so that the NaN guards keep their meaning. Throughput against scipy,
fraction of the machine's peak and the variants tried: bench/flight_benchmark.py (its figures:
bench/RESULTS.md).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from numba import njit, prange
import numpy as np

from . import dop853, dynamics as dyn
from .aero import AeroModel, resolve
from .presets import BallPreset
from .step_stability import MIN_AIR_SPEED


_STAGES = dop853.N_STAGES
_A = np.zeros((_STAGES, _STAGES))
for _i, _row in dop853.A.items():
    for _j, _a in _row.items():
        _A[_i, _j] = _a
_B = np.array([dop853.B.get(j, 0.0) for j in range(_STAGES)])
N_LEAN = 13  # r, v, s, h, h1
STEP_PER_RADIAN = 1.1
"""Default step = STEP_PER_RADIAN / (fastest rate, :func:`fastest_rates`), at most MAX_STEP:
about 1.1 rad of the fastest mode per step; the angle error grows as step^8
(bench/flight_benchmark.py prints it against a tight DOP853 solution)."""
MAX_STEP = 0.04


@njit(cache=True, inline='always')
def _rate(speed, h, h1, params):
    """
    Fastest rate [1/s] of the motion at air speed ``speed`` [m/s], |h| and |h1| [rad/s].

    The axis' rotation |h| (nutation, |h1| for a spiral) or 2 sqrt(M) (a ball tumbling in the
    overturning moment M_alpha plus the Magnus moment's stiffness), plus the damping and force
    rates (pitch and spin damping, lift, drag, Magnus force).
    """
    spin = params[dyn.P_SPIN_RATIO] * h1
    damp = params[dyn.P_DAMP_K] * speed
    stiffness = params[dyn.P_MOMENT_K] * speed * speed + damp * spin * abs(params[dyn.P_CMPA])
    turning = max(h, 2.0 * math.sqrt(stiffness))
    damping = damp * (abs(params[dyn.P_CMQ]) + abs(params[dyn.P_CLP]) * params[dyn.P_SPIN_RATIO])
    forces = params[dyn.P_FORCE_K] * (
        speed * (params[dyn.P_CD0] + params[dyn.P_CD2] + abs(params[dyn.P_CLA]))
        + spin * params[dyn.P_DIAMETER] * abs(params[dyn.P_CNPA])
    )
    return turning + damping + forces


@njit(cache=True)
def _rates(speed, h, h1, params):
    out = np.empty(speed.size)
    for i in range(speed.size):
        out[i] = _rate(speed[i], h[i], h1[i], params)
    return out


def fastest_rates(y0: np.ndarray, params: np.ndarray, ground: float = 0.0) -> np.ndarray:
    """
    Return the fastest rate [1/s] of each ball's motion (lean states y0).

    At the largest air speed its flight can reach: energy bound sqrt(V^2 + 2 g z) (capped at
    the terminal speed when there is drag) plus twice the wind. This sets each block's step;
    during the flight the kernel shortens it if the current rates grow beyond it (a Magnus
    moment can pump the wobble).
    """
    v = y0[:, 3:6]
    z = np.maximum(y0[:, 2] - ground, 0.0)
    g = params[dyn.P_GRAVITY]
    wind = np.linalg.norm(params[dyn.P_WIND:dyn.P_WIND + 3])
    speed = np.sqrt(np.sum(v * v, axis=1) + 2.0 * g * z)
    fk = params[dyn.P_FORCE_K]
    if fk * params[dyn.P_CD0] > 1e-9:
        terminal = math.sqrt(g / (fk * params[dyn.P_CD0]))
        speed = np.minimum(speed, np.maximum(np.linalg.norm(v, axis=1), terminal))
    speed = speed + 2.0 * wind
    return _rates(speed, np.linalg.norm(y0[:, 9:12], axis=1), np.abs(y0[:, 12]), params)


def default_steps(rates: np.ndarray) -> np.ndarray:
    """Step [s] for balls of the given :func:`fastest_rates` [1/s]."""
    return np.minimum(MAX_STEP, STEP_PER_RADIAN / np.maximum(rates, 1e-9))


# _block_derivative, _block_step and dynamics.loads are inlined into the prange body, where the
# block arrays are allocated: LLVM then knows they do not alias and vectorises over the balls
# (measured 2.3x faster than calls). Inlined numba IR is compiled with the flags of the function
# it lands in: _integrate_batch's _FASTMATH, not the fastmath=True written here.
@njit(cache=True, fastmath=True, inline='always')
def _block_derivative(y, params, out, nb):
    """d/dt of the lean states in columns 0..nb-1 of y (N_LEAN, BLOCK) into out."""
    for b in range(nb):
        sx, sy, sz = y[6, b], y[7, b], y[8, b]
        hx, hy, hz = y[9, b], y[10, b], y[11, b]
        ax, ay, az, dhx, dhy, dhz, dh1 = dyn.loads(
            (y[3, b], y[4, b], y[5, b]), (sx, sy, sz), (hx, hy, hz), y[12, b], params
        )
        out[0, b], out[1, b], out[2, b] = y[3, b], y[4, b], y[5, b]
        out[3, b], out[4, b], out[5, b] = ax, ay, az
        out[6, b] = hy * sz - hz * sy  # s' = h x s
        out[7, b] = hz * sx - hx * sz
        out[8, b] = hx * sy - hy * sx
        out[9, b], out[10, b], out[11, b] = dhx, dhy, dhz
        out[12, b] = dh1


def _block_step_source() -> str:
    """
    Source of ``_block_step``: the DOP853 stage sums written out term by term.

    The tableau's non-zero coefficients become literals, so that each sum is one expression
    (fused multiply-adds in registers, one store per state component and ball) instead of a
    loop over coefficients reading and writing the stage state once per term. The stage states
    skip the position (the derivative does not read it).
    """
    src = [
        'def _block_step(y, dt, params, k, tmp, out, nb):',
        '    for i in range(_STAGES):',  # one derivative in the code, the sums chosen by i
        '        stage = y',
    ]
    for i in range(1, _STAGES):
        cols = np.nonzero(_A[i])[0]
        terms = ' + '.join(f'a{c} * k[{c}, j, b]' for c in cols)
        src += [f'        {"if" if i == 1 else "elif"} i == {i}:']
        src += [f'            a{c} = dt * {float(_A[i, c])!r}' for c in cols]
        src += [
            '            for j in range(3, N_LEAN):',
            '                for b in range(nb):',
            f'                    tmp[j, b] = y[j, b] + ({terms})',
            '            stage = tmp',
        ]
    src += ['        _block_derivative(stage, params, k[i], nb)']
    cols = np.nonzero(_B)[0]
    src += [f'    a{c} = dt * {float(_B[c])!r}' for c in cols]
    terms = ' + '.join(f'a{c} * k[{c}, j, b]' for c in cols)
    src += [
        '    for j in range(N_LEAN):',
        '        for b in range(nb):',
        f'            out[j, b] = y[j, b] + ({terms})',
        '    _project(out, nb)',
    ]
    return '\n'.join(src) + '\n'


@njit(cache=True, inline='always')
def _project(out, nb):
    """|s| = 1 and h.s = h1 in columns 0..nb-1."""
    for b in range(nb):
        norm = math.sqrt(out[6, b] ** 2 + out[7, b] ** 2 + out[8, b] ** 2)
        out[6, b] /= norm
        out[7, b] /= norm
        out[8, b] /= norm
        err = out[12, b] - (
            out[9, b] * out[6, b] + out[10, b] * out[7, b] + out[11, b] * out[8, b]
        )
        out[9, b] += err * out[6, b]
        out[10, b] += err * out[7, b]
        out[11, b] += err * out[8, b]


_namespace = {
    '_block_derivative': _block_derivative,
    '_project': _project,
    'N_LEAN': N_LEAN,
    '_STAGES': _STAGES,
}
exec(compile(_block_step_source(), '<dop853 block step>', 'exec'), _namespace)
_block_step = njit(inline='always')(_namespace['_block_step'])
_block_step.__doc__ = """
One DOP853 (8th-order weights) step of every column, then |s| = 1 and h.s = h1.

Columns are balls: the inner loops run over balls, so the compiler can use SIMD lanes.
"""


@njit(cache=True)
def hermite(p0, d0, p1, d1, dt, u):
    """
    Return the cubic Hermite interpolant at fraction ``u`` in [0, 1] of a step of ``dt`` [s].

    ``p0``, ``p1``: the values at the step's ends, ``d0``, ``d1``: their time derivatives (per
    second); the one interpolant of sampled flights (batch landings, the planner's crossings).
    """
    u2, u3 = u * u, u * u * u
    return (
        (2 * u3 - 3 * u2 + 1) * p0
        + (u3 - 2 * u2 + u) * dt * d0
        + (-2 * u3 + 3 * u2) * p1
        + (u3 - u2) * dt * d1
    )


@njit(cache=True)
def _hermite_root(z0, d0, z1, d1, h, ground):
    """
    Return the fraction u of a step of length h where the Hermite z reaches ``ground``.

    z is the cubic Hermite interpolant; bisection; z0 above, z1 at or below it.
    """
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if hermite(z0, d0, z1, d1, h, mid) > ground:
            lo = mid
        else:
            hi = mid
    return hi


@njit(cache=True)
def _curved(y, nxt, j, b, h, u):
    """
    |cubic Hermite - quadratic| at fraction u for coordinate j (velocity j + 3) of column b.

    A bound on the cubic's interpolation error, which is far smaller (~ h^4 vs h^3).
    """
    p0, d0, p1 = y[j, b], y[j + 3, b], nxt[j, b]
    quadratic = p0 + d0 * h * u + (p1 - p0 - d0 * h) * u * u
    return abs(hermite(p0, d0, p1, nxt[j + 3, b], h, u) - quadratic)


@njit(cache=True, fastmath=True)
def _landing(y, nxt, b, h, params, ground, out):
    """
    Fraction u of the step of length h from column b of y to nxt at which z = ground.

    The state there (a partial step from y) into out[:, 0]. The root of the cubic Hermite
    interpolant of z is taken, the state computed there, and, if z misses the ground there by
    more than 1e-12 m, the bracket narrowed on it (at most 3 rounds: the interpolation error
    shrinks as the bracket's length^4).
    """
    one = np.empty((N_LEAN, 1))
    k = np.empty((_STAGES, N_LEAN, 1))
    tmp = np.empty((N_LEAN, 1))
    for j in range(N_LEAN):
        one[j, 0] = y[j, b]
    lo, hi = 0.0, 1.0
    z0, d0, z1, d1 = y[2, b], y[5, b], nxt[2, b], nxt[5, b]
    u = 1.0
    for _ in range(3):
        a, c = 0.0, 1.0  # bisection on the interpolant over [lo, hi]
        for _ in range(60):
            mid = 0.5 * (a + c)
            if hermite(z0, d0, z1, d1, (hi - lo) * h, mid) > ground:
                a = mid
            else:
                c = mid
        u = lo + c * (hi - lo)
        _block_step(one, u * h, params, k, tmp, out, 1)
        miss = out[2, 0] - ground  # the interpolant's error there
        if abs(miss) <= 1e-12 * (1.0 + abs(ground)) or hi - lo < 1e-15:
            break  # usually after the first round: one scalar partial step per landing
        if miss > 0.0:
            lo, z0, d0 = u, out[2, 0], out[5, 0]
        else:
            hi, z1, d1 = u, out[2, 0], out[5, 0]
    return u


_FASTMATH = {'contract', 'arcp', 'nsz', 'reassoc'}
"""Fast-math flags of the kernel: not 'nnan'/'ninf' (the guards test for NaN)."""
BLOCK = 32
"""Balls integrated together by one thread (SIMD lanes along the ball index)."""


@njit(parallel=True, cache=True, fastmath=_FASTMATH)
def _integrate_batch(
    y0, params, steps, max_time, ground, sample_every, samples, results, adaptive
):
    """
    Integrate every row of y0 (N, N_LEAN) in blocks of BLOCK rows.

    Block b with step steps[b] (if ``adaptive``, shortened whenever the block's current fastest
    rate needs it); results (N, 7) = landing x, y, time, landed, max|alpha|, max|beta|, max
    delta. ``samples`` (N, M, 2) gets alpha, beta every ``sample_every`` steps.
    """
    n_balls = y0.shape[0]
    n_blocks = (n_balls + BLOCK - 1) // BLOCK
    wx, wy, wz = params[dyn.P_WIND], params[dyn.P_WIND + 1], params[dyn.P_WIND + 2]
    for blk in prange(n_blocks):
        first = blk * BLOCK
        nb = min(BLOCK, n_balls - first)
        dt = steps[blk]
        y = np.empty((N_LEAN, BLOCK))
        nxt = np.empty((N_LEAN, BLOCK))
        tmp = np.empty((N_LEAN, BLOCK))
        k = np.empty((_STAGES, N_LEAN, BLOCK))
        flying = np.ones(BLOCK, np.bool_)
        worst = np.empty((4, BLOCK))
        at = np.empty((N_LEAN, 1))
        for b in range(nb):
            ball = first + b
            y[:, b] = y0[ball]
            s1, s2, s3 = dyn.velocity_frame_components(  # against the air: v - wind
                (y[3, b] - wx, y[4, b] - wy, y[5, b] - wz), (y[6, b], y[7, b], y[8, b])
            )
            # Extremes are kept as components (no trigonometry per step): the largest |alpha|
            # as the pair (|s2|, s1) of largest angle, the largest |beta| as max |s3|, the
            # largest delta as min s1; angles are taken once at the end.
            worst[0, b], worst[1, b], worst[2, b], worst[3, b] = abs(s2), s1, abs(s3), s1
            results[ball, 2], results[ball, 3] = max_time, 0.0
            if samples.shape[1] > 0:
                samples[ball, 0, 0] = math.atan2(s2, s1)
                samples[ball, 0, 1] = math.asin(min(1.0, max(-1.0, s3)))
        left = nb
        t = 0.0
        i = -1
        last = False
        while not last:
            i += 1
            h = dt
            if adaptive:
                fastest = 0.0
                for b in range(nb):
                    if flying[b]:
                        speed = math.sqrt(
                            (y[3, b] - params[dyn.P_WIND]) ** 2
                            + (y[4, b] - params[dyn.P_WIND + 1]) ** 2
                            + (y[5, b] - params[dyn.P_WIND + 2]) ** 2
                        )
                        hn = math.sqrt(y[9, b] ** 2 + y[10, b] ** 2 + y[11, b] ** 2)
                        fastest = max(fastest, _rate(speed, hn, abs(y[12, b]), params))
                if fastest * h > 1.05 * STEP_PER_RADIAN:  # (margin: the wobble moves |h| a little)
                    h = STEP_PER_RADIAN / fastest
            if t + h >= max_time - 1e-9 * h:  # the last step ends at max_time
                h = max_time - t
                last = True
            _block_step(y, h, params, k, tmp, nxt, nb)
            j = (i + 1) // sample_every
            keep_sample = (i + 1) % sample_every == 0 and j < samples.shape[1]
            for b in range(nb):
                if not flying[b]:
                    continue
                ball = first + b
                # Above the ground (or on it at the release, going up), then at or below it.
                above = y[2, b] > ground or (i == 0 and y[2, b] == ground and y[5, b] > 0.0)
                if above and nxt[2, b] <= ground and nxt[5, b] < 0.0:
                    u = _hermite_root(y[2, b], y[5, b], nxt[2, b], nxt[5, b], h, ground)
                    if (
                        _curved(y, nxt, 0, b, h, u)
                        + _curved(y, nxt, 1, b, h, u)
                        + _curved(y, nxt, 2, b, h, u)
                    ) > 1e-6:
                        # Far from a parabola: locate it on exact partial steps instead.
                        u = _landing(y, nxt, b, h, params, ground, at)
                        results[ball, 0], results[ball, 1] = at[0, 0], at[1, 0]
                    else:
                        results[ball, 0] = hermite(y[0, b], y[3, b], nxt[0, b], nxt[3, b], h, u)
                        results[ball, 1] = hermite(y[1, b], y[4, b], nxt[1, b], nxt[4, b], h, u)
                    results[ball, 2] = t + u * h
                    results[ball, 3] = 1.0
                    flying[b] = False
                    left -= 1
                    continue
                ux, uy, uz = nxt[3, b] - wx, nxt[4, b] - wy, nxt[5, b] - wz  # air-relative
                horizontal = ux**2 + uy**2
                if not horizontal > 1e-20 * (horizontal + uz**2):
                    continue  # vertical air velocity: alpha and beta are undefined
                s1, s2, s3 = dyn.velocity_frame_components(
                    (ux, uy, uz), (nxt[6, b], nxt[7, b], nxt[8, b])
                )
                if abs(s2) * worst[1, b] > worst[0, b] * s1:
                    worst[0, b], worst[1, b] = abs(s2), s1
                worst[2, b] = max(worst[2, b], abs(s3))
                worst[3, b] = min(worst[3, b], s1)
                if keep_sample:
                    samples[ball, j, 0] = math.atan2(s2, s1)
                    samples[ball, j, 1] = math.asin(min(1.0, max(-1.0, s3)))
            y[:, :] = nxt
            t += h
            if left == 0:
                break
        for b in range(nb):
            ball = first + b
            if flying[b]:
                results[ball, 0], results[ball, 1] = y[0, b], y[1, b]
            results[ball, 4] = math.atan2(worst[0, b], worst[1, b])
            results[ball, 5] = math.asin(min(1.0, worst[2, b]))
            results[ball, 6] = math.acos(max(-1.0, min(1.0, worst[3, b])))


@dataclass(frozen=True)
class BatchResult:
    """
    Per-ball results.

    landing_x, landing_y [m], time_of_flight [s] (max_time if not landed), landed (bool),
    max_alpha, max_beta, max_delta [rad] over the flight, and, when asked for, samples (N, M,
    2) of alpha, beta [rad] at multiples of ``sample_period``.
    """

    landing_x: np.ndarray
    landing_y: np.ndarray
    time_of_flight: np.ndarray
    landed: np.ndarray
    max_alpha: np.ndarray
    max_beta: np.ndarray
    max_delta: np.ndarray
    samples: np.ndarray | None
    sample_period: float


def lean_states(ball: BallPreset, states: dict[str, np.ndarray]) -> np.ndarray:
    """(N, N_LEAN) batch states from :func:`football_ros.physics.release.release_states`."""
    n = states['velocity'].shape[0]
    y = np.empty((n, N_LEAN))
    y[:, 0:3] = states['position']
    y[:, 3:6] = states['velocity']
    y[:, 6:9] = states['axis']
    h1 = ball.inertia_ratio * states['spin']
    y[:, 9:12] = states['transverse_rate'] + h1[:, None] * states['axis']
    y[:, 12] = h1
    return y


def simulate_batch(
    ball: BallPreset,
    states: dict[str, np.ndarray],
    model: str = 'paper',
    moment: str = 'linear',
    aero: AeroModel | None = None,
    step: float | None = None,
    max_time: float = 20.0,
    ground: float = 0.0,
    sample_period: float | None = None,
    sample_count: int = 0,
) -> BatchResult:
    """
    Fly N balls until each lands on z = ground or ``max_time`` [s] passes.

    Same ball and model, releases from ``states``. ``step`` [s]: None = the default rule
    (module docstring).

    Raises ValueError if a release moves with the wind (no air speed: its angles and the
    loads' direction are undefined), as
    :func:`football_ros.physics.step_stability.check_flyable` does.
    """
    ball, aero = resolve(ball, model, aero)
    y0 = lean_states(ball, states)
    params = dyn.make_params(ball, moment, aero)
    air = np.linalg.norm(y0[:, 3:6] - params[dyn.P_WIND:dyn.P_WIND + 3], axis=1)
    if not np.all(air > MIN_AIR_SPEED):
        bad = int(np.argmin(air))
        raise ValueError(
            f'release {bad} moves with the wind (air speed {air[bad]:.3g} m/s < '
            f'{MIN_AIR_SPEED:g} m/s): its angle of attack is undefined'
        )
    n = y0.shape[0]
    n_blocks = (n + BLOCK - 1) // BLOCK
    rates = fastest_rates(y0, params, ground)
    if step is None and not sample_count:
        # Blocks of balls with similar rates, each with its own step.
        order = np.argsort(rates, kind='stable')
        padded = np.pad(rates[order], (0, n_blocks * BLOCK - n), mode='edge')
        steps = default_steps(padded.reshape(n_blocks, BLOCK).max(axis=1))
    else:
        order = np.arange(n)
        if step is None:
            step = float(default_steps(rates.max(initial=0.0)))
        steps = np.full(n_blocks, step)
    every = 1
    if sample_count:
        every = int(round((sample_period or steps[0]) / steps[0]))
        if every < 1 or abs(every * steps[0] - (sample_period or steps[0])) > 1e-9 * steps[0]:
            raise ValueError('sample_period must be a whole multiple of the step')
    samples = np.full((n, sample_count, 2), np.nan)
    results = np.empty((n, 7))
    _integrate_batch(
        np.ascontiguousarray(y0[order]),
        params,
        steps,
        max_time,
        ground,
        every,
        samples,
        results,
        step is None and not sample_count,
    )
    unsorted = np.empty_like(results)
    unsorted[order] = results
    return BatchResult(
        unsorted[:, 0],
        unsorted[:, 1],
        unsorted[:, 2],
        unsorted[:, 3] > 0.5,
        unsorted[:, 4],
        unsorted[:, 5],
        unsorted[:, 6],
        samples if sample_count else None,
        every * steps[0],
    )
