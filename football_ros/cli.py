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
``football-ros``: command-line front end.

Headless commands (no ROS needed): ``modes``, ``simulate``, ``montecarlo``, ``plot``,
``paper``, ``compile``. Node commands (``simulator``, ``release``, ``tracker``, ``record``,
``demo``, ``echo``, ``throw``) need rclpy and pass ``--ros-args`` through. Bad options print
one line on stderr and exit with code 2. Start-up: numba, matplotlib and rclpy are imported
only by the commands that integrate, draw or talk to ROS (``modes`` and ``--help`` need none).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from typing import Sequence, TYPE_CHECKING

from .command_line import add_release_options, Parser, release_from_args, UsageError
from .physics import PRESETS, Release, ReleaseError
from .physics.modes import modes_report
from .programs import ros_commands

if TYPE_CHECKING:
    from .physics import Flight

EXIT_USAGE = 2
DESCRIPTION = 'football-ros: a spinning American football or rugby ball in flight (ROS 2 Jazzy).'

NODE_COMMANDS = ros_commands()
"""Command -> (module, function) of the commands that need rclpy and parse their own options."""


def _print_modes(report: dict) -> None:
    def hz(w):
        return '' if w is None else f'rad/s ({w / (2 * math.pi):.3f} Hz)'

    def deg(x):
        return f'rad ({math.degrees(x):.3f} deg)'

    full = report['model'] == 'full'
    wind = report['wind']
    rows = [
        ('ball', report['ball'], ''),
        ('model', report['model'], ''),
        ('wind', ' '.join(f'{w:g}' for w in wind), 'm/s (field)'),
        ('ground speed', f'{report["ground_speed"]:.3f}', 'm/s'),
        ('air speed V = |v - wind|', f'{report["speed"]:.3f}', 'm/s'),
        ('flight-path angle Phi', f'{math.degrees(report["flight_path_angle"]):.2f}', 'deg (air)'),
        ('', '', ''),
        ('paper linear theory (frozen)', '', 'torque only, V and Phi at release'),
        ('M_alpha', f'{report["m_alpha"]:.3f}', '1/s^2'),
        ('h1 = (I_s/I_t) p', f'{report["h1"]:.3f}', 'rad/s'),
        ('omega_fast (nutation)', f'{report["omega_fast"]:.4f}', hz(report['omega_fast'])),
        ('omega_slow (precession)', f'{report["omega_slow"]:.4f}', hz(report['omega_slow'])),
        (
            'gyroscopically stable',
            'yes' if report['stable'] else f'NO (grows at {report["growth_rate"]:.3f} 1/s)',
            'h1^2 > 4 M_alpha',
        ),
        ('S_g = h1^2 / (4 M_alpha)', f'{report["gyroscopic_stability_factor"]:.3f}', ''),
        ('critical spin', f'{report["critical_spin_rpm"]:.1f}', 'rpm'),
        (
            'equilibrium sideslip s3p',
            f'{report["equilibrium_sideslip"]:.5f}',
            f'rad ({math.degrees(report["equilibrium_sideslip"]):.3f} deg, > 0 nose right)',
        ),
        ('C1 (fast mode)', f'{report["c1"][0]:+.5f} {report["c1"][1]:+.5f}i', 'rad'),
        ('C2 (slow mode)', f'{report["c2"][0]:+.5f} {report["c2"][1]:+.5f}i', 'rad'),
    ]
    if full:
        f = report['full']
        rows += [
            ('', '', ''),
            ('full model at release', '', 'its own linear equation (lift, damping, Magnus)'),
            ('omega_fast', _fmt(f['omega_fast'], '.4f'), hz(f['omega_fast'])),
            ('omega_slow', _fmt(f['omega_slow'], '.4f'), hz(f['omega_slow'])),
            ('equilibrium alpha', f'{f["equilibrium_alpha"]:.5f}', deg(f['equilibrium_alpha'])),
            ('equilibrium beta', f'{f["equilibrium_beta"]:.5f}', deg(f['equilibrium_beta'])),
        ]
    rows += [
        ('', '', ''),
        ('mode damping rates', '', '1/s, < 0 decays'),
        ('fast, level flight', _fmt(report['fast_damping_rate'], '+.4f'), 'speed change: drag'),
        ('slow, level flight', _fmt(report['slow_damping_rate'], '+.4f'), 'speed change: drag'),
        (
            'fast, at the release angle',
            _fmt(report['fast_damping_rate_gravity'], '+.4f'),
            'drag + g sin(Phi)',
        ),
        (
            'slow, at the release angle',
            _fmt(report['slow_damping_rate_gravity'], '+.4f'),
            'drag + g sin(Phi)',
        ),
        (
            'dynamically stable',
            _yes_no(report['dynamically_stable']),
            'both level-flight rates < 0' if full else 'full model only',
        ),
        (
            'reference: S_d = 2T/H (McCoy)',
            _fmt(report['dynamic_stability_factor'], '.3f'),
            (
                'McCoy: ' + ('stable' if report['mccoy_dynamically_stable'] else 'unstable')
                + ' (assumes spin falling with speed)'
            )
            if full
            else 'full model only',
        ),
    ]
    width = max(len(r[0]) for r in rows) + 2
    indent = ''  # the release's own rows first, then indented sections
    for name, value, unit in rows:
        if not value and not unit:
            print()
        elif not value:
            print(f'{name}: {unit}')
            indent = '  '
        else:
            print(f'{indent + name:<{width}}  {value:>20}  {unit}'.rstrip())


def _yes_no(value) -> str:
    return 'n/a' if value is None else ('yes' if value else 'NO')


def _fmt(value, spec: str) -> str:
    return 'n/a' if value is None else format(value, spec)


def _cmd_modes(args: argparse.Namespace) -> int:
    report = modes_report(release_from_args(args))
    if args.json:
        import json

        print(json.dumps(report, indent=2))
    else:
        _print_modes(report)
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    from .tools.flightdata import write_sidecar

    release = release_from_args(args)
    if not (0.0 < args.duration <= 600.0):
        raise UsageError(f'--duration must be in (0, 600] s, got {args.duration}')
    if not (0.0 < args.rate <= 100000.0):
        raise UsageError(f'--rate must be in (0, 100000] Hz, got {args.rate}')
    if not (0.0 < args.step <= 0.05):
        raise UsageError(f'--step must be in (0, 0.05] s, got {args.step}')
    from .physics import Flight

    check_output_file(args.out, '--out')
    flight = Flight.from_release(release, step=args.step)
    trajectory = flight.simulate(rate=args.rate, duration=args.duration)
    warnings = simulate_warnings(release, flight, trajectory)
    trajectory.write_csv(args.out)
    sidecar = write_sidecar(
        args.out,
        release,
        flight.ball,
        flight.aero,
        {
            'step': args.step,
            'rate': args.rate,
            'duration': args.duration,
            'landed': bool(trajectory.landed),
            'end_time': float(trajectory.times[-1]),
            'warnings': warnings,
        },
    )
    for text in warnings:
        print(f'football-ros: warning: {text}', file=sys.stderr)
    end = 'landed' if trajectory.landed else 'stopped at the duration'
    print(
        f'{len(trajectory.times)} rows to {args.out} (what they are: {sidecar}); {end} at '
        f't = {trajectory.times[-1]:.4f} s, x = {trajectory.positions[-1, 0]:.3f} m, '
        f'y = {trajectory.positions[-1, 1]:.3f} m',
        file=sys.stderr,
    )
    return 0


def simulate_warnings(release: Release, flight: 'Flight', trajectory) -> list[str]:
    """
    Sentences about a simulated flight the user must know.

    A gyroscopically unstable release, and the model forms whose data range the flight's total
    angle left.
    """
    import numpy as np

    from .physics.aero import max_valid_delta, out_of_validity

    out = []
    modes = flight.modes
    if not modes.stable:
        out.append(
            f'the release is gyroscopically UNSTABLE: spin {release.spin_rpm:g} rpm is '
            f'below the critical {modes.critical_spin_rpm:.0f} rpm '
            f'(S_g = {modes.gyroscopic_stability_factor:.2f} < 1); the ball tumbles and '
            f'the linear theory does not apply'
        )
    delta = trajectory.aero_angles[:, 2]
    if delta.size:
        worst = int(np.argmax(delta))
        worst_delta = float(delta[worst])
        texts = out_of_validity(
            worst_delta, release.model, release.moment, flight.aero, flight.ball
        )
        for text in texts:
            out.append(f'{text}; largest at t = {trajectory.times[worst]:.2f} s')
        limit = max_valid_delta(release.model, release.moment, flight.aero)
        beyond = np.flatnonzero(delta > limit)
        if texts and beyond.size:
            out.append(
                f'the flight first leaves the data range ({math.degrees(limit):g} deg) '
                f'at t = {trajectory.times[beyond[0]]:.2f} s'
            )
    return out


def check_output_file(path: str, option: str) -> None:
    """Raise UsageError now (before any work) if ``path`` cannot be written as a file."""
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise UsageError(f'{option} {path}: is a folder, not a file')
    if not os.path.isdir(folder):
        raise UsageError(f'{option} {path}: folder {folder} does not exist')
    if not os.access(folder, os.W_OK | os.X_OK) or (
        os.path.exists(path) and not os.access(path, os.W_OK)
    ):
        raise UsageError(f'{option} {path}: not writable')


def _cmd_montecarlo(args: argparse.Namespace) -> int:
    import time

    start = time.perf_counter()
    release = release_from_args(args)
    from .tools import montecarlo as mc

    try:
        spread = mc.parse_spread(args.spread)
        mc.check_spread(release, spread)
        out, figure = mc.output_paths(args.out, args.figure)
        zone = mc.check_zone(args.zone, args.until_halfwidth)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    parquet = out is not None and out.suffix.lower() == '.parquet'
    most = mc.BALLS_MAX if parquet or out is None else mc.GATHERED_MAX
    if not 1 <= args.n <= most:
        raise UsageError(
            f'--n must be in [1, {most}], got {args.n}'
            + ('' if most == mc.BALLS_MAX else ' (more balls: --out DIR.parquet or none)')
        )
    if args.seed < 0:
        raise UsageError(f'--seed must be >= 0, got {args.seed}')
    if args.workers is not None and args.scheduler is not None:
        raise UsageError('--workers and --scheduler exclude each other')
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise UsageError(f'--workers must be in [1, 256], got {args.workers}')
    if not 1 <= args.task_chunks <= 10_000:
        raise UsageError(f'--task-chunks must be in [1, 10000], got {args.task_chunks}')
    if out is not None and not parquet:
        check_output_file(str(out), '--out')
    if figure is not None:
        check_output_file(str(figure), '--out (figure)')
    drawing = None
    if figure is not None:  # a child process imports matplotlib meanwhile
        drawing = mc.FigureProcess(
            figure,
            f'{args.n} releases around {release.ball} {release.speed:g} m/s, '
            f'{release.elevation_deg:g} deg, {release.spin_rpm:g} rpm ({release.model} model)',
        )
    try:
        outcome = mc.run(
            release,
            args.n,
            spread,
            args.seed,
            progress=not args.quiet,
            parquet=out if parquet else None,
            workers=args.workers,
            scheduler=args.scheduler,
            zone=zone,
            until_halfwidth=args.until_halfwidth,
            task_chunks=args.task_chunks,
            gather=out is not None,
        )
        if drawing is not None:
            drawing.draw(mc.figure_data(outcome))
        if out is not None and not parquet:
            mc.write(out, outcome.rows)
        for line in mc.warnings(outcome, release):
            print(f'football-ros: warning: {line}', file=sys.stderr)
        print('\n'.join(mc.summary(outcome, release, spread)))
    except KeyboardInterrupt:  # the cluster is closed by now; no traceback
        print('football-ros: montecarlo interrupted', file=sys.stderr)
        return 130
    finally:
        drew = drawing is None or drawing.finish()
    if not drew:
        return 1
    print(
        (f'per-ball results: {out}' if out is not None else 'per-ball results: none (--out none)')
        + (' (Parquet partitions, one per task: pyarrow.dataset.dataset(DIR))' if parquet else '')
        + (f'\nfigure: {figure}' if figure else '')
        + f'\ntotal {time.perf_counter() - start:.2f} s'
    )
    return 0


def _cmd_compile(args: argparse.Namespace) -> int:
    from . import numba_cache_dir
    from .physics.precompile import compile_ahead

    where = numba_cache_dir() or 'beside the sources (__pycache__)'
    print(f'football-ros compile: numba kernels; cache: {where}', flush=True)
    steps = compile_ahead(lambda line: print(line, flush=True) if not args.quiet else None)
    from .estimation.tracker import warm_up as tracker_kernels
    from .simulation.kernel import warm_up as world_kernel
    from .tools.fastcsv import warm_up as csv_writer

    # the simulator's world, the Monte Carlo CSV, the tracker
    for warm_up in (world_kernel, csv_writer, tracker_kernels):
        steps.append(warm_up())
        if not args.quiet:
            print(f'[+] {steps[-1].name}: {steps[-1].seconds:.1f} s', flush=True)
    total = sum(step.seconds for step in steps)
    compiled = sum(step.compiled for step in steps)
    print(f'ready: {compiled} kernel(s) compiled, the rest loaded, in {total:.1f} s', flush=True)
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from .tools.figures import plot_source

    for path in plot_source(args.source, args.out, args.ball, args.spin_rpm):
        print(path)
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    from .tools import paper

    for path in paper.run(args.out):
        print(path)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog='football-ros',
        description=DESCRIPTION,
        epilog="'football-ros COMMAND --help' describes each command.",
    )
    sub = parser.add_subparsers(
        dest='command', required=True, parser_class=Parser, metavar='COMMAND'
    )

    def add(name: str, text: str) -> argparse.ArgumentParser:
        return sub.add_parser(name, help=text, description=text[0].upper() + text[1:] + '.')

    p = add(
        'modes',
        'linear-theory modes, damping rates, stability and equilibrium of a release as '
        "'simulate' flies it (against the air; --model full: the full model's own)",
    )
    add_release_options(p)
    p.add_argument('--json', action='store_true', help='print JSON instead of a table')
    p.set_defaults(func=_cmd_modes)
    p = add('simulate', 'integrate a flight headless and write a CSV')
    add_release_options(p)
    p.add_argument('--duration', type=float, default=10.0, help='max simulated time [s]')
    p.add_argument('--rate', type=float, default=100.0, help='output rows per second [Hz]')
    p.add_argument('--step', type=float, default=1e-3, help='integration step [s]')
    p.add_argument(
        '--out',
        required=True,
        help='CSV file to write (and <out>.json beside it: the release, ball, model)',
    )
    p.set_defaults(func=_cmd_simulate)
    p = add('montecarlo', 'landing dispersion and wobble statistics of release errors')
    add_release_options(p)
    p.add_argument(
        '--n',
        type=int,
        default=10000,
        help='number of balls (the most, with --until-halfwidth; CSV/.npz: up to 10^7)',
    )
    p.add_argument(
        '--spread',
        action='append',
        default=[],
        metavar='KEY=[DIST:]WIDTH[,...]',
        help='error of a release quantity, e.g. speed=0.5,spin_rpm=uniform:50,'
        'speed=lognormal:0.02: DIST normal (WIDTH = sigma, the default), uniform '
        '(+-WIDTH) or lognormal (nominal x exp(WIDTH z)); defaults: normal, speed 0.5 m/s, '
        'angles 1 deg, spin 30 rpm, rates 10 deg/s',
    )
    p.add_argument(
        '--seed',
        type=int,
        default=0,
        help='random seed (>= 0): the rows depend on it alone, not on workers or chunks',
    )
    p.add_argument(
        '--zone',
        nargs=3,
        type=float,
        metavar=('X', 'Y', 'R'),
        help='target zone on the ground: the probability of landing within R m of (X, Y) '
        '[m, field], with its Wilson 95 %% interval',
    )
    p.add_argument(
        '--until-halfwidth',
        type=float,
        metavar='H',
        help='with --zone: fly chunks of 10^4 balls until the interval half-width is <= H '
        '(at most --n balls)',
    )
    p.add_argument(
        '--workers',
        type=int,
        help='run on a local Dask cluster of N worker processes (default: in this process)',
    )
    p.add_argument(
        '--scheduler',
        metavar='ADDRESS',
        help='run on an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (workers need '
        'football_ros installed, and the --out folder for Parquet)',
    )
    p.add_argument(
        '--task-chunks',
        type=int,
        default=1,
        help='chunks of 10^4 balls per Dask task (and per Parquet partition)',
    )
    p.add_argument('--quiet', action='store_true', help='no progress bar')
    p.add_argument(
        '--out',
        required=True,
        help='per-ball results: FILE.csv (text), FILE.npz (numpy arrays, loads '
        "10^6 balls in a fraction of the CSV's time), DIR.parquet (partitions written by "
        "the workers, for any --n; load lazily with pyarrow.dataset), or 'none' (statistics "
        'only, for any --n; a figure only with --figure FILE.png)',
    )
    p.add_argument(
        '--figure',
        default='auto',
        help="PNG file, 'auto' = the --out name with .png, 'none' = no figure",
    )
    p.set_defaults(func=_cmd_montecarlo)
    p = add('compile', 'compile (first time) or load every numba kernel ahead of use')
    p.add_argument('--quiet', action='store_true', help='only the final line')
    p.set_defaults(func=_cmd_compile)
    p = add('plot', 'figures (PNG) from a recorded bag or a simulate CSV')
    p.add_argument('source', help="bag folder / .mcap file, or CSV from 'simulate'")
    p.add_argument('--out', required=True, help='folder for the PNG files')
    p.add_argument(
        '--ball',
        choices=list(PRESETS),
        help='the ball, when the file does not say (a CSV without its .csv.json '
        'sidecar, a bag without football/flight/order)',
    )
    p.add_argument(
        '--spin-rpm',
        type=float,
        help="spin for the equilibrium curve (default: recorded, else the release's)",
    )
    p.set_defaults(func=_cmd_plot)
    p = sub.add_parser(
        'paper',
        help="the paper's Figure 3-8 cases (PNG) and report.md: its "
        "numbers against this package's",
    )
    p.add_argument('--out', required=True, help='folder for the PNG files and report.md')
    p.set_defaults(func=_cmd_paper)
    from .tools import plan as plan_tool  # its options only; the planner loads when it runs

    p = add('plan', 'the release that takes the ball through a target, with the least wobble')
    plan_tool.add_plan_options(p)
    p.set_defaults(func=plan_tool.run)
    for name in NODE_COMMANDS:
        sub.add_parser(name, help=f'{name} (ROS; see football-ros {name} --help)', add_help=False)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; the exit code. A closed output pipe (``| head``) ends it quietly."""
    try:
        code = _main(argv)
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        # The reader went away: send the rest of the output nowhere and exit quietly.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0


def _main(argv: Sequence[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in NODE_COMMANDS:
        import importlib

        module_name, function = NODE_COMMANDS[argv[0]]
        return getattr(importlib.import_module(module_name), function)(argv[1:]) or 0
    try:
        args = build_parser().parse_args(argv)
        return args.func(args)
    except (UsageError, ReleaseError) as exc:
        print(f'football-ros: error: {exc}', file=sys.stderr)
        return EXIT_USAGE
    except ValueError as exc:  # unreadable plot source
        print(f'football-ros: error: {exc}', file=sys.stderr)
        return EXIT_USAGE
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            raise
        print(
            f'football-ros: error: {exc.strerror or exc}: {exc.filename or ""}'.rstrip(': '),
            file=sys.stderr,
        )
        return EXIT_USAGE


if __name__ == '__main__':
    sys.exit(main())
