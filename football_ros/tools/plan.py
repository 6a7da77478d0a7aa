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
``football-ros plan``: the release that takes the ball through a target.

The release options give the base release (ball, spin and hand, release point, model, aero,
wind; ``--speed`` is the speed of the flat and lofted arcs); the planner chooses speed,
elevation, azimuth and the least-wobble attitude. ``--json`` prints one object whose release
keys (``speed``, ``elevation_deg``, ... ``beta_rate_deg_s``, ``position``, ``model``, ``aero``)
are a release: ``football-ros simulate --plan PLAN.json`` flies it. An infeasible
target exits 1 with the reason; ``--throw`` sends the plan to a running release node
(``football-ros throw``) and prints its answer.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from ..command_line import add_release_options, key_values, release_from_args, UsageError
from ..physics.release import Release

EXIT_INFEASIBLE = 1
MAX_PLAN_BYTES = 1 << 20
"""Largest plan file ``simulate --plan`` reads [bytes] (a plan is about 2 kB)."""


def add_plan_options(parser: argparse.ArgumentParser) -> None:
    """Add the plan command's options (the release options included)."""
    g = parser.add_argument_group('target')
    g.add_argument('--target', type=float, nargs=3, metavar=('X', 'Y', 'Z'),
                   help='point in field [m] the ball centre must pass through')
    g.add_argument('--receiver', type=float, nargs=6, metavar=('X', 'Y', 'Z', 'VX', 'VY', 'VZ'),
                   help='a moving receiver instead: position [m] and velocity [m/s] in field')
    g.add_argument('--receiver-time', type=float, default=0.0,
                   help='time [s] after the release at which the receiver is at X Y Z')
    g.add_argument('--arrival-time', type=float, help='wanted arrival time [s] after release')
    g.add_argument('--arrival-window', type=float, nargs=2, metavar=('T0', 'T1'),
                   help='accepted arrival times [s]')
    g = parser.add_argument_group('plan')
    g.add_argument('--objective', default='fastest',
                   choices=('fastest', 'lowest_speed', 'flat', 'lofted'),
                   help='fastest: flat arc at --max-speed; flat/lofted: at --speed; '
                   'lowest_speed: the least speed')
    g.add_argument('--max-speed', type=float, default=35.0, help='largest release speed [m/s]')
    g.add_argument('--elevation-range', type=float, nargs=2, default=(-45.0, 80.0),
                   metavar=('MIN', 'MAX'), help='accepted release elevations [deg]')
    g.add_argument('--attitude', default='equilibrium',
                   choices=('equilibrium', 'linear', 'refined', 'aligned'),
                   help='release attitude: least wobble (quasi-steady equilibrium), the '
                   'frozen C1 = C2 = 0 one, refined over the nonlinear flight, or aligned')
    g.add_argument('--tolerance', type=float, default=0.01, help='largest accepted miss [m]')
    g.add_argument('--hit-n', type=int, default=2000,
                   help='balls for the hit probability under release noise (0 = skip)')
    g.add_argument('--catch-radius', type=float, default=0.5, help='catch radius [m]')
    g.add_argument('--sigma', action='append', default=[], metavar='KEY=SIGMA',
                   help='release-error sigma, e.g. speed=0.5 (defaults: those of montecarlo)')
    g.add_argument('--compare-arcs', action='store_true',
                   help='also plan the flat and the lofted arc at --speed and say which one '
                   'hits more often (--target only)')
    g = parser.add_argument_group('output')
    g.add_argument('--json', action='store_true', help='print the plan as one JSON object')
    g.add_argument('--throw', action='store_true',
                   help='send the plan to a running release node and print its answer')
    g.add_argument('--id', default=None, help='release request id for --throw')
    g.add_argument('--timeout', type=float, default=10.0, help='seconds to wait for --throw')
    add_release_options(parser)


def release_from_plan(path: str) -> Release:
    """
    Return the release of a ``plan --json`` output file (``simulate --plan``).

    The release keys of :meth:`Release.to_mapping` are taken, the plan's other numbers are not
    read. Raises :class:`UsageError` naming the file and what is wrong with it.
    """
    from ..strict_yaml import load_strict, StrictParseError

    where = f'--plan {path}'
    try:
        with open(path, 'rb') as handle:
            raw = handle.read(MAX_PLAN_BYTES + 1)
    except OSError as exc:
        raise UsageError(f'{where}: cannot read it ({exc.strerror})') from None
    if len(raw) > MAX_PLAN_BYTES:
        raise UsageError(f'{where}: more than {MAX_PLAN_BYTES} bytes, not a plan')
    try:
        data = load_strict(raw.decode('utf-8'))
    except UnicodeDecodeError:
        raise UsageError(f'{where}: not UTF-8 text') from None
    except StrictParseError as exc:
        raise UsageError(f'{where}: {exc}') from None
    if not isinstance(data, dict):
        raise UsageError(f"{where}: not one JSON object (the output of 'football-ros plan "
                         "--json')")
    missing = [key for key in Release.FIELDS if key not in data]
    if missing:
        raise UsageError(f"{where}: no {', '.join(missing)} (the output of 'football-ros plan "
                         "--json' has every release key)")
    try:
        return Release.from_mapping({key: data[key] for key in Release.FIELDS})
    except (TypeError, ValueError) as exc:  # ReleaseError, or a wrongly typed entry
        raise UsageError(f'{where}: {exc}') from None


def throw_argv(release_mapping: dict[str, Any], request_id: str | None,
               timeout: float) -> list[str]:
    """Return ``football-ros throw`` arguments that send this release (its options)."""
    r = release_mapping
    argv = ['--ball', r['ball'], '--model', r['model'], '--moment', r['moment']]
    for key in ('speed', 'elevation_deg', 'azimuth_deg', 'spin_rpm', 'alpha0_deg', 'beta0_deg',
                'alpha_rate_deg_s', 'beta_rate_deg_s'):
        argv += [f'--{key.replace("_", "-")}', repr(float(r[key]))]
    argv += ['--position', *(repr(float(v)) for v in r['position'])]
    for key, value in r['ball_params'].items():
        argv += ['--ball-param', f'{key}={value!r}']
    for key, value in r['aero'].items():
        if key == 'wind':
            argv += ['--wind', *(repr(float(v)) for v in value)]
        elif value is not None:
            argv += ['--aero', f'{key}={json.dumps(value)}']
    if request_id:
        argv += ['--id', request_id]
    return argv + ['--timeout', repr(float(timeout))]


def json_safe(value: Any) -> Any:
    """Return JSON-safe data: NaN and infinities as null, arrays as lists."""
    if hasattr(value, 'tolist'):
        value = value.tolist()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    return value


def run(args: argparse.Namespace) -> int:
    """Plan, print, optionally throw; the exit code."""
    if (args.target is None) == (args.receiver is None):
        raise UsageError('give exactly one of --target and --receiver')
    base = release_from_args(args)
    sigmas = key_values(args.sigma, '--sigma', float)
    from ..planning import hit_probability, plan, PlanError, Receiver

    receiver = None
    if args.receiver is not None:
        receiver = Receiver(args.receiver[:3], args.receiver[3:], args.receiver_time)
    try:
        the_plan = plan(
            args.target,
            base,
            objective=args.objective,
            max_speed=args.max_speed,
            elevation_range=tuple(args.elevation_range),
            receiver=receiver,
            arrival_time=args.arrival_time,
            arrival_window=None if args.arrival_window is None else tuple(args.arrival_window),
            attitude=args.attitude,
            tolerance=args.tolerance,
        )
    except PlanError as exc:
        print(f'football-ros plan: error: {exc}', file=sys.stderr)
        return EXIT_INFEASIBLE
    out = the_plan.to_mapping()
    if args.hit_n > 0:
        try:
            est = hit_probability(the_plan, sigmas, args.catch_radius, args.hit_n)
            out.update(est.to_mapping())
        except PlanError as exc:
            out['hit_probability'] = None
            out['hit_probability_note'] = str(exc)
    if args.compare_arcs and args.target is not None:
        from ..planning import arcs_summary, compare_arcs

        comparison = compare_arcs(
            args.target, base, sigmas, args.catch_radius, max(args.hit_n, 100),
            max_speed=args.max_speed, elevation_range=tuple(args.elevation_range),
            attitude=args.attitude, tolerance=args.tolerance)
        out['arcs'] = arcs_summary(comparison)
    out = json_safe(out)
    if args.json:
        print(json.dumps(out))
    else:
        _print_plan(out)
    if args.throw:
        from ..nodes.console import throw

        sys.stdout.flush()
        return throw(throw_argv(the_plan.release_mapping(), args.id, args.timeout))
    return 0


def _print_plan(p: dict[str, Any]) -> None:
    rows = [
        ('speed', p['speed'], 'm/s'),
        ('elevation', p['elevation_deg'], 'deg'),
        ('azimuth', p['azimuth_deg'], 'deg'),
        ('spin', p['spin_rpm'], 'rpm'),
        ('alpha0', p['alpha0_deg'], 'deg'),
        ('beta0', p['beta0_deg'], 'deg'),
        ('alpha rate', p['alpha_rate_deg_s'], 'deg/s'),
        ('beta rate', p['beta_rate_deg_s'], 'deg/s'),
        ('arrival time', p['arrival_time'], 's'),
        ('miss', p['miss_m'], 'm'),
        ('axis-velocity angle at arrival', p['arrival_delta_deg'], 'deg'),
        ('wobble amplitude', p['wobble_deg'], 'deg (largest axis-equilibrium angle)'),
        ('aligned release: angle at arrival', p['aligned_arrival_delta_deg'], 'deg'),
        ('aligned release: wobble amplitude', p['aligned_wobble_deg'], 'deg'),
    ]
    print(f"plan ({p['objective']}, {p['arc']} arc) to target "
          f"({p['target'][0]:.2f}, {p['target'][1]:.2f}, {p['target'][2]:.2f}) m")
    for name, value, unit in rows:
        text = 'n/a' if value is None else f'{value:.4f}'
        print(f'{name:<36}{text:>12}  {unit}')
    print(f"attitude: {p['attitude_sentence']}")
    if p.get('hit_probability') is not None:
        print(f"hit probability (catch radius {p['catch_radius_m']:g} m): "
              f"{p['hit_probability']:.3f} [{p['hit_probability_low']:.3f}, "
              f"{p['hit_probability_high']:.3f}] (95 %, {p['hit_n']} balls)")
    elif p.get('hit_probability_note'):
        print(f"hit probability: n/a ({p['hit_probability_note']})")
    arcs = p.get('arcs')
    if arcs:
        for arc in ('flat', 'lofted'):
            if f'{arc}_refused' in arcs:
                print(f"{arc} arc: refused ({arcs[f'{arc}_refused']})")
            else:
                print(f"{arc} arc: elevation {arcs[f'{arc}_elevation_deg']:.2f} deg, arrival "
                      f"{arcs[f'{arc}_arrival_time']:.3f} s, hit probability "
                      f"{arcs[f'{arc}_hit_probability']:.3f} "
                      f"[{arcs[f'{arc}_hit_probability_low']:.3f}, "
                      f"{arcs[f'{arc}_hit_probability_high']:.3f}]")
        print(f"more robust: {arcs['more_robust']} (either: the intervals overlap)")
    for warning in p['warnings']:
        print(f'warning: {warning}')
