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
Headless speed at equal accuracy: one flight, and a batch of flights, against scipy solve_ivp.

    .venv/bin/python bench/flight_benchmark.py [--n 20000] [--model paper|full] [--asm|--zmm]

The batch's floating-point work is estimated by counting (FLOPS_* below: the terms of
dynamics.loads and the DOP853 stage sums; a sqrt or a division counts 1) times the steps its
blocks take; the machine's peak is measured in the same run as the best of 3 float64 matrix
products (numpy's BLAS, 2048^2, every core), and the fraction reached is printed, also of the
256-bit peak: the same product on OpenBLAS's AVX2 kernel (OPENBLAS_CORETYPE=Haswell, in a
child process), what code kept to 256-bit vectors can reach. ``--asm`` counts the compiled
kernel's float64 instructions by vector width; ``--zmm`` times the batch with LLVM's default
vectors and with 512-bit ones (child processes, alternating).

Reference: solve_ivp DOP853 with rtol = atol = 1e-13 on the s/h form of the equations
(docs/physics.md section 2; written out here independently of football_ros). Every contender's
max |alpha|, |beta| difference from it is printed. The baseline is solve_ivp DOP853 with the
right-hand side compiled by numba (:func:`rhs_compiled`) at the loosest tolerance (rtol =
10^-k, atol = rtol / 100) whose error is no larger than football_ros's own: the same accuracy.
The targets are <= 1e-6 rad, >= 10x for one flight, >= 1e5 ball-seconds per second for the
batch. Times are the best of three runs, all measured in this run on this machine.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

from football_ros.physics import Flight, frames, get_preset, Release
from football_ros.physics.batch import simulate_batch
from football_ros.physics.release import release_states
from numba import njit
import numpy as np
from scipy.integrate import solve_ivp

G = 9.81
FLOPS_LOADS = 114  # dynamics.loads: air velocity, |u|, u_hat, cos, u_hat x s, forces, moments
FLOPS_DERIVATIVE = FLOPS_LOADS + 9  # + s' = h x s
FLOPS_PER_STEP_EXTRA = 90  # projection, landing test, velocity-frame extremes, step check


def flops_per_step() -> int:
    """
    Floating-point operations one DOP853 step of one ball needs (the scheme, not a kernel).

    12 derivatives; the stage sums over the tableau's non-zero coefficients (50 in A, 8 in b;
    a multiply and an add each), the stages on the 10 components the derivative reads (not the
    position), the step on all 13: the useful work the fractions of peak count.
    """
    from football_ros.physics import batch as bt

    n_a = int(np.count_nonzero(bt._A))
    n_b = int(np.count_nonzero(bt._B))
    stage_sums = 2 * ((bt.N_LEAN - 3) * n_a + bt.N_LEAN * n_b)
    return bt._STAGES * FLOPS_DERIVATIVE + stage_sums + FLOPS_PER_STEP_EXTRA


def steps_taken(ball, states, model, tof) -> float:
    """Count the steps the batch takes (its default step rule, balls sorted and blocked so)."""
    from football_ros.physics import batch as bt
    from football_ros.physics import dynamics as dyn
    from football_ros.physics.aero import resolve

    b, aero = resolve(ball, model, None)
    y0 = bt.lean_states(b, states)
    rates = bt.fastest_rates(y0, dyn.make_params(b, 'linear', aero))
    order = np.argsort(rates, kind='stable')
    n_blocks = (len(rates) + bt.BLOCK - 1) // bt.BLOCK
    padded = np.pad(rates[order], (0, n_blocks * bt.BLOCK - len(rates)), mode='edge')
    steps = np.repeat(bt.default_steps(padded.reshape(n_blocks, bt.BLOCK).max(axis=1)), bt.BLOCK)
    tof_blocks = np.pad(tof[order], (0, n_blocks * bt.BLOCK - len(rates)))
    # A block steps until its last ball lands; every lane computes meanwhile.
    return float(
        np.sum(
            tof_blocks.reshape(n_blocks, bt.BLOCK).max(axis=1)
            / steps.reshape(n_blocks, bt.BLOCK)[:, 0]
        )
        * bt.BLOCK
    )


def peak_flops() -> float:
    """Measured float64 peak [flop/s]: best of 3 BLAS matrix products 2048 x 2048 (all cores)."""
    a, b = np.random.rand(2048, 2048), np.random.rand(2048, 2048)
    seconds, _ = best_of(lambda: a @ b)
    return 2 * 2048**3 / seconds


def peak_flops_256() -> float:
    """
    Measure the dgemm peak with 256-bit vectors only [flop/s] (nan if it cannot be measured).

    OpenBLAS (numpy's BLAS, built for every x86 core type) is told to use its Haswell kernel
    (AVX2 + FMA, 256-bit) with OPENBLAS_CORETYPE in a child process: the peak that LLVM's code
    can reach when it keeps to 256-bit vectors, as it does by default on AVX-512 machines.
    """
    code = (
        'import time, numpy as np\n'
        'a, b = np.random.rand(2048, 2048), np.random.rand(2048, 2048)\n'
        'best = float("inf")\n'
        'for _ in range(3):\n'
        '    t = time.perf_counter(); a @ b; best = min(best, time.perf_counter() - t)\n'
        'print(2 * 2048**3 / best)\n'
    )
    env = dict(os.environ, OPENBLAS_CORETYPE='Haswell')
    try:
        out = subprocess.run(
            [sys.executable, '-c', code], env=env, capture_output=True, text=True, timeout=120
        )
        return float(out.stdout.strip())
    except (OSError, ValueError, subprocess.SubprocessError):
        return float('nan')


def kernel_census() -> dict:
    """
    Count the floating-point arithmetic instructions of the compiled batch kernel by width.

    Keys (operation, 'packed'/'scalar', register): operation add/sub/mul/div/sqrt/fma, register
    xmm (128-bit or scalar), ymm (256), zmm (512); static counts over the prange body (the
    parfor gufunc), not executed counts. Compiles afresh in a temporary cache (numba cannot
    show the assembly of cached code): about 20 s.
    """
    import re
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        code = (
            'import numpy as np\n'
            'from football_ros.physics import get_preset\n'
            'from football_ros.physics.batch import _integrate_batch, simulate_batch\n'
            'from football_ros.physics.release import release_states\n'
            'st = release_states(np.full(40, 27.0), 30.0, 0.0, 600.0, 0.0, 0.0, 0.0, 0.0,'
            ' np.zeros(3))\n'
            "simulate_batch(get_preset('american'), st)\n"
            'print(_integrate_batch.inspect_asm(_integrate_batch.signatures[0]))\n'
        )
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        asm = subprocess.run(
            [sys.executable, '-c', code], env=env, capture_output=True, text=True, check=True
        ).stdout
    lines = asm.splitlines()
    start = next(i for i, line in enumerate(lines) if '__numba_parfor_gufunc' in line
                 and line.endswith(':') and not line.startswith('__gufunc__'))
    counts: dict = {}
    op = re.compile(r'v(f?n?m?)(add|sub|mul|div|sqrt)\w*?(sd|pd)$')
    for line in lines[start + 1:]:
        if re.match(r'^[_A-Za-z]\S*:$', line):
            break  # the next function
        words = line.split()
        match = op.match(words[0]) if words else None
        if match:
            name = 'fma' if match.group(1) else match.group(2)
            width = next((r for r in ('zmm', 'ymm') if r in line), 'xmm')
            key = (name, 'packed' if match.group(3) == 'pd' else 'scalar', width)
            counts[key] = counts.get(key, 0) + 1
    return counts


@njit(cache=True)
def rhs_compiled(_t, y, k, g):
    """
    Return y' of the s/h equations (docs/physics.md section 2): y = (r, v, s, h), compiled.

    r' = v, v' = (0, 0, -g), s' = h x s, h' = k |v| (v x s).
    """
    out = np.empty(12)
    vx, vy, vz = y[3], y[4], y[5]
    sx, sy, sz = y[6], y[7], y[8]
    hx, hy, hz = y[9], y[10], y[11]
    speed = np.sqrt(vx * vx + vy * vy + vz * vz)
    out[0], out[1], out[2] = vx, vy, vz
    out[3], out[4], out[5] = 0.0, 0.0, -g
    out[6], out[7], out[8] = hy * sz - hz * sy, hz * sx - hx * sz, hx * sy - hy * sx
    ks = k * speed
    out[9], out[10], out[11] = (ks * (vy * sz - vz * sy), ks * (vz * sx - vx * sz),
                                ks * (vx * sy - vy * sx))
    return out


def ivp_angles(ball, st, index, times, rtol, atol):
    """Angles (alpha, beta) [rad] at ``times`` of ball ``index`` by solve_ivp DOP853."""
    s0 = st['axis'][index]
    h0 = st['transverse_rate'][index] + ball.inertia_ratio * st['spin'][index] * s0
    y0 = np.concatenate([st['position'][index], st['velocity'][index], s0, h0])
    sol = solve_ivp(
        rhs_compiled,
        (0.0, times[-1]),
        y0,
        method='DOP853',
        rtol=rtol,
        atol=atol,
        t_eval=times,
        args=(ball.moment_coefficient(), G),
    )
    return frames.aero_angles(sol.y[6:9].T, sol.y[3:6].T)[:, :2]


def best_of(fn, repeat=3):
    best, out = float('inf'), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def one_flight() -> tuple[list[tuple], float]:
    """
    Fly a 3 s flight (released 10 m up so it does not land), sampled at 100 Hz.

    Returns the two rows (football_ros, the baseline at the same error) and the baseline's
    rtol.
    """
    release = Release(
        position=(0.0, 0.0, 10.0),
        alpha0_deg=3.0,
        beta0_deg=-2.0,
        alpha_rate_deg_s=20.0,
        beta_rate_deg_s=-10.0,
    )
    ball = release.preset()
    st = release_states(
        release.speed,
        release.elevation_deg,
        0.0,
        release.spin_rpm,
        3.0,
        -2.0,
        20.0,
        -10.0,
        np.array(release.position),
    )
    times = np.arange(301) * 0.01
    ref = ivp_angles(ball, st, 0, times, 1e-13, 1e-13)
    Flight.from_release(release).simulate(rate=100.0, duration=3.0)  # compile / load the kernel
    t_ours, tr = best_of(lambda: Flight.from_release(release).simulate(rate=100.0, duration=3.0))
    err_ours = np.max(np.abs(tr.aero_angles[:, :2] - ref))
    for rtol in 10.0 ** -np.arange(5, 13):  # the loosest tolerance as accurate as ours
        err_ivp = np.max(np.abs(ivp_angles(ball, st, 0, times, rtol, rtol * 1e-2) - ref))
        if err_ivp <= err_ours:
            break
    t_ivp, ang = best_of(lambda: ivp_angles(ball, st, 0, times, rtol, rtol * 1e-2))
    err_ivp = np.max(np.abs(ang - ref))
    return [
        ('one 3 s flight: football_ros (RK4, 1 ms)', t_ours, err_ours),
        (f'one 3 s flight: solve_ivp DOP853 rtol={rtol:g}, compiled RHS', t_ivp, err_ivp),
    ], rtol


def batch_states(n: int, rng: np.random.Generator) -> dict:
    """Return the batch's releases: a nominal spiral pass with spreads."""
    return release_states(
        27.4 + rng.normal(0, 1.0, n),
        30 + rng.normal(0, 2.0, n),
        rng.normal(0, 1.0, n),
        600 + rng.normal(0, 40.0, n),
        rng.normal(0, 2.0, n),
        rng.normal(0, 2.0, n),
        rng.normal(0, 15.0, n),
        rng.normal(0, 15.0, n),
        np.zeros(3),
    )


def batch_seconds_512(n: int, model: str, rounds: int = 4) -> tuple[float, float]:
    """
    Time the batch [s] with LLVM's default vectors and with 512-bit ones, in child processes.

    512-bit: NUMBA_CPU_FEATURES = the host's features with '-prefer-256-bit' (LLVM otherwise
    keeps to 256-bit vectors on AVX-512 machines), compiled into its own cache (once: ~20 s).
    The two children alternate ``rounds`` times; each time is the best of 3.
    """
    import tempfile

    import llvmlite.binding as llvm

    features = llvm.get_host_cpu_features().flatten() + ',-prefer-256-bit'
    code = (
        'import sys, time\n'
        f'sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r})\n'
        'import numpy as np\n'
        'from flight_benchmark import batch_states, best_of\n'
        'from football_ros.physics import get_preset\n'
        'from football_ros.physics.batch import simulate_batch\n'
        f'st = batch_states({n}, np.random.default_rng(7))\n'
        "ball = get_preset('american')\n"
        f'simulate_batch(ball, {{k: v[:64] for k, v in st.items()}}, {model!r})\n'
        f'print(best_of(lambda: simulate_batch(ball, st, {model!r}))[0])\n'
    )
    cache = os.path.join(tempfile.gettempdir(), 'football_ros_bench_512')
    wide = dict(os.environ, NUMBA_CPU_FEATURES=features, NUMBA_CACHE_DIR=cache)
    best = [float('inf'), float('inf')]
    for _ in range(rounds):
        for i, env in enumerate((dict(os.environ), wide)):
            out = subprocess.run(
                [sys.executable, '-c', code], env=env, capture_output=True, text=True, check=True
            )
            best[i] = min(best[i], float(out.stdout.split()[-1]))
    return best[0], best[1]


def batch(
    n: int, model: str, baseline_rtol: float, n_ivp: int
) -> tuple[list[tuple], float, float]:
    rng = np.random.default_rng(7)
    ball = get_preset('american')
    st = batch_states(n, rng)
    simulate_batch(
        ball, {k: v[:64] for k, v in st.items()}, model
    )  # compile / load, start threads
    t_batch, res = best_of(lambda: simulate_batch(ball, st, model))
    ball_seconds = float(res.time_of_flight.sum())
    # Accuracy of the batch on a few balls, sampled every 4 steps over the first 2.5 s.
    picks = rng.choice(n, size=8, replace=False)
    sub = {k: v[picks] for k, v in st.items()}
    probe = simulate_batch(ball, sub, 'paper', sample_count=1)
    step = probe.sample_period
    count = int(2.5 / (4 * step))
    sampled = simulate_batch(ball, sub, 'paper', sample_period=4 * step, sample_count=count)
    times = np.arange(count) * 4 * step
    err_batch = max(
        np.max(np.abs(sampled.samples[i] - ivp_angles(ball, sub, i, times, 1e-13, 1e-13)))
        for i in range(len(picks))
    )

    # The per-ball solve_ivp loop, on n_ivp balls, to each ball's landing time.
    def ivp_loop():
        errs = []
        for i in range(n_ivp):
            t_end = res.time_of_flight[i]
            grid = np.linspace(0.0, t_end, 100)
            errs.append(ivp_angles(ball, st, i, grid, baseline_rtol, baseline_rtol * 1e-2))
        return errs

    t_ivp, _ = best_of(ivp_loop, repeat=1)
    ivp_ball_seconds = float(res.time_of_flight[:n_ivp].sum())
    rows = [
        (
            f'batch of {n} ({model} model)',
            t_batch,
            err_batch if model == 'paper' else float('nan'),
        ),
        (f'solve_ivp loop, {n_ivp} balls', t_ivp, float('nan')),
    ]
    lanes = steps_taken(ball, st, model, res.time_of_flight)
    work = lanes * flops_per_step()
    return (
        rows,
        ball_seconds / t_batch,
        ivp_ball_seconds / t_ivp,
        work / t_batch,
        work / ball_seconds,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--n', type=int, default=20000, help='balls in the batch')
    parser.add_argument('--n-ivp', type=int, default=20, help='balls in the solve_ivp loop')
    parser.add_argument('--model', default='paper', choices=('paper', 'full'))
    parser.add_argument(
        '--asm', action='store_true', help="count the kernel's vector instructions and stop"
    )
    parser.add_argument(
        '--zmm',
        action='store_true',
        help='time the batch with 256-bit and 512-bit vectors (child processes) and stop',
    )
    args = parser.parse_args()
    if args.zmm:
        default, wide = batch_seconds_512(args.n, args.model)
        print(
            f'batch of {args.n} ({args.model}): {default:.4f} s with 256-bit vectors, '
            f'{wide:.4f} s with 512-bit vectors: {default / wide:.2f}x'
        )
        return
    if args.asm:
        print('float64 arithmetic instructions of the batch kernel (static, prange body):')
        for key, count in sorted(kernel_census().items()):
            print(f'  {" ".join(key):<24}{count:>6}')
        return
    rows, rtol = one_flight()
    batch_rows, rate, ivp_rate, flop_rate, flop_per_ball_s = batch(
        args.n, args.model, rtol, args.n_ivp
    )
    peak = peak_flops()
    peak_256 = peak_flops_256()
    print(
        f'\nfootball_ros headless speed, {os.cpu_count()} cores '
        '(best of 3; errors vs DOP853 rtol=atol=1e-13)\n'
    )
    print(f'{"contender":<58}{"time [s]":>12}{"max alpha/beta err [rad]":>26}')
    for name, seconds, err in rows + batch_rows:
        print(
            f'{name:<58}{seconds:>12.4f}{err:>26.2e}'
            if np.isfinite(err)
            else f'{name:<58}{seconds:>12.4f}{"-":>26}'
        )
    print(
        f'\none flight: football_ros is {rows[1][1] / rows[0][1]:.0f}x faster than solve_ivp '
        '(target >= 10x)'
    )
    print(
        f'batch: {rate:.3g} ball-seconds per second vs {ivp_rate:.3g} for the solve_ivp loop '
        f'({rate / ivp_rate:.0f}x); target >= 1e5'
    )
    print(
        f'batch work: {flops_per_step()} flop per ball-step, {flop_per_ball_s:.3g} flop per '
        f'ball-second -> {flop_rate / 1e9:.1f} GFLOP/s; measured peak (BLAS dgemm, '
        f'{os.cpu_count()} cores) {peak / 1e9:.1f} GFLOP/s: '
        f'{100 * flop_rate / peak:.0f} % of it'
    )
    print(
        f'256-bit peak (the same dgemm on its AVX2 kernel, OPENBLAS_CORETYPE=Haswell): '
        f'{peak_256 / 1e9:.1f} GFLOP/s: {100 * flop_rate / peak_256:.0f} % of it'
    )


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('flight', main))
