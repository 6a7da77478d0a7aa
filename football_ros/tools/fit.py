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
``football-ros fit``: coefficients from measured flights (the inverse of ``simulate``).

Reads each TRACK (:mod:`.tracks`), fits every flight's release state and the freed
coefficients at once (:mod:`football_ros.identification`) and prints a table of coefficient,
value, 95 % interval and identifiable, or with ``--json`` one object::

    {"coefficients": {name: {"value", "ci95": [lo, hi], "identifiable", ...}},
     "residual_rms_m", "flights": [...], "correlation", "simulate_args", ...}

A coefficient that is not identifiable has value and ci95 null and a reason. ``simulate_args``
are the options that make ``football-ros simulate`` fly the fitted model: the identifiable
coefficients through ``--aero KEY=VALUE`` (the names ``simulate --aero`` takes),
``--ball-param c_m_alpha=...``, ``--spin-rpm`` and ``--wind``, with the fixed settings given
here. ``--out DIR`` writes fit.json and two figures: the residuals and the fitted paths.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
import sys
from typing import Any, TYPE_CHECKING

from .plan import json_safe
from ..command_line import key_values, UsageError
from ..identification.coefficients import (
    ALIASES, COEFFICIENTS, DEFAULT_FREE, parse_free, RELEASE_RATES
)
from ..physics import PRESETS
from ..physics.aero import AeroModel
from ..physics.presets import get_preset
from ..physics.release import MODELS, MOMENT_CURVES

if TYPE_CHECKING:
    from ..identification.fit import FitResult
    from ..identification.problem import FitSettings

AERO_NAMES = ('c_d0', 'c_d2', 'c_l_alpha', 'c_n_p_alpha', 'c_m_q', 'c_l_p')
"""Freed coefficients that ``simulate --aero`` takes by the same name."""


def add_fit_options(parser: argparse.ArgumentParser) -> None:
    """Add the fit command's options."""
    parser.add_argument('tracks', nargs='+', metavar='TRACK',
                        help='CSV with columns t,x,y,z [sx,sy,sz] [sigma] (field, SI; one '
                        'flight), or a bag (folder or .mcap/.db3) with football/observation '
                        "or a ball's pose topic")
    parser.add_argument('--ball', required=True, choices=list(PRESETS), help='the ball')
    parser.add_argument('--model', default='full', choices=MODELS, help='the model fitted')
    parser.add_argument('--moment', default='linear', choices=MOMENT_CURVES,
                        help='overturning moment curve (as simulate)')
    parser.add_argument('--free', metavar='NAME[,NAME...]',
                        help='what to fit, from '
                        + ', '.join(f'{n} ({c.text})' for n, c in COEFFICIENTS.items())
                        + ' (aliases: '
                        + ', '.join(f'{a} = {",".join(v)}' for a, v in ALIASES.items())
                        + f'; default: {",".join(DEFAULT_FREE["full"])} for the full model, '
                        f'{",".join(DEFAULT_FREE["paper"])} for the paper model)')
    parser.add_argument('--noise', type=float, metavar='SIGMA',
                        help='noise of the fixes without a sigma column, 1 sigma per axis '
                        '[m] (default: estimated from the residuals)')
    parser.add_argument('--axis-noise', type=float, metavar='DEG',
                        help='noise of the observed axes, 1 sigma per component [deg] '
                        '(default: estimated)')
    parser.add_argument('--spin-rpm', type=float,
                        help="release spin [rpm] (default: the ball's nominal; the start "
                        'value when the spin is freed)')
    parser.add_argument('--aero', action='append', default=[], metavar='KEY=VALUE',
                        help='fixed full-model setting (and start value of a freed one), as '
                        'simulate takes it (repeatable)')
    parser.add_argument('--ball-param', action='append', default=[], metavar='KEY=VALUE',
                        help='override a ball parameter, e.g. c_m_alpha=0.3 (repeatable)')
    parser.add_argument('--release-rate', default='auto', choices=RELEASE_RATES,
                        help="each flight's transverse angular velocity at release (its "
                        'wobble): fitted (free), zero (held), or auto: fitted for flights with '
                        'observed axes; for the others held unless freeing it fits their '
                        'positions significantly better (default auto)')
    parser.add_argument('--topic', help='the bag topic to read (default: football/observation, '
                        'else the one pose topic)')
    parser.add_argument('--no-profile', action='store_true',
                        help='intervals from the Jacobian alone (no profile-likelihood check)')
    parser.add_argument('--json', action='store_true', help='print one JSON object')
    parser.add_argument('--out', metavar='DIR',
                        help='folder for fit.json, residuals.png and paths.png')


def settings_from_args(args: argparse.Namespace) -> 'FitSettings':
    """Return the fit settings the options say; UsageError naming a bad one."""
    import yaml

    from ..identification.problem import FitSettings

    for name, value, lo, hi in (('--noise', args.noise, 0.0, 10.0),
                                ('--axis-noise', args.axis_noise, 0.0, 90.0),
                                ('--spin-rpm', args.spin_rpm, -3000.0, 3000.0)):
        if value is not None and not (math.isfinite(value) and lo <= value <= hi
                                      and (value > 0.0 or name == '--spin-rpm')):
            raise UsageError(f'{name} must be in ({lo:g}, {hi:g}], got {value}')
    try:
        ball = get_preset(args.ball, key_values(args.ball_param, '--ball-param', float))
        aero = AeroModel.from_mapping(key_values(args.aero, '--aero', yaml.safe_load))
    except (ValueError, TypeError) as exc:
        raise UsageError(str(exc)) from None
    if args.model == 'paper' and args.aero:
        raise UsageError('--aero is for the full model (--model full)')
    free = None if args.free is None else tuple(args.free.split(','))
    try:  # before any file is read
        parse_free(free, args.model, aero if args.model == 'full' else None)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    return FitSettings(
        ball, args.model, args.moment, aero if args.model == 'full' else None, free,
        args.spin_rpm, args.noise,
        None if args.axis_noise is None else math.radians(args.axis_noise),
        release_rate=args.release_rate, profile=not args.no_profile,
    )


def run(args: argparse.Namespace) -> int:
    """Read, fit, print (and write ``--out``); the exit code."""
    from ..identification.fit import fit
    from .tracks import read_tracks

    settings = settings_from_args(args)
    out_dir = None
    if args.out is not None:
        out_dir = Path(args.out)
        if out_dir.exists() and not out_dir.is_dir():
            raise UsageError(f'--out {out_dir}: not a folder')
    tracks, warnings = [], []
    for path in args.tracks:
        read, notes = read_tracks(path, args.topic)
        tracks += read
        warnings += notes
    result = fit(tracks, settings)
    report = to_mapping(result, args)
    report['warnings'] = warnings + report['warnings']
    if args.json:
        print(json.dumps(report))
    else:
        print_report(report)
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / 'fit.json').write_text(json.dumps(report, indent=2) + '\n')
        for path in write_figures(result, out_dir):
            print(f'figure: {path}', file=sys.stderr)
    for text in report['warnings']:
        print(f'football-ros fit: warning: {text}', file=sys.stderr)
    return 0


def to_mapping(result: 'FitResult', args: argparse.Namespace) -> dict[str, Any]:
    """Return the report as plain data (the module docstring's JSON object)."""
    coefficients = {
        name: {
            'value': c.value,
            'ci95': None if c.ci95 is None else list(c.ci95),
            'identifiable': c.identifiable,
            'unit': c.unit,
            'sigma': c.sigma,
            'interval': c.interval,
            'reason': c.reason or None,
        }
        for name, c in result.coefficients.items()
    }
    flights = [
        {
            'source': f.name,
            'fixes': int(f.times.size),
            't0': f.t0,
            'duration_s': float(f.times[-1]),
            'residual_rms_m': f.residual_rms_m,
            'axis_residual_rms_deg': f.axis_residual_rms_deg,
            'release': {'position': f.position, 'velocity': f.velocity, 'axis': f.axis,
                        'transverse_rate': f.transverse_rate,
                        'transverse_rate_fitted': f.rate_fitted, 'spin_rpm': f.spin_rpm},
        }
        for f in result.flights
    ]
    argv, warnings = simulate_args(result, args)
    if not result.converged:
        warnings.append('the fit stopped at its iteration limit before converging')
    for name, c in result.coefficients.items():
        lo, hi = COEFFICIENTS[name].physical
        if c.identifiable and (c.ci95[1] < lo or c.ci95[0] > hi):
            warnings.append(f'{name}: its 95 % interval is outside its physical range '
                            f'[{lo:g}, {hi:g}]: the model does not fit these flights (a wrong '
                            'held value, or flights of another model)')
    return json_safe({
        'coefficients': coefficients,
        'residual_rms_m': result.residual_rms_m,
        'flights': flights,
        'correlation': {'names': list(result.coefficients), 'matrix': result.correlation},
        'noise_m': result.noise_m,
        'axis_noise_deg': result.axis_noise_deg,
        'chi2': result.chi2,
        'dof': result.dof,
        'iterations': result.iterations,
        'converged': result.converged,
        'ball': result.ball,
        'model': result.model,
        'moment': result.moment,
        'fixed': result.fixed,
        'simulate_args': argv,
        'warnings': warnings,
    })


def simulate_args(result: 'FitResult', args: argparse.Namespace) -> tuple[list[str], list[str]]:
    """
    Return the ``football-ros simulate`` options of the fitted model, and warnings.

    The fixed settings given to ``fit`` (``--aero``, ``--ball-param``) and each identifiable
    coefficient; one outside what ``simulate`` accepts is left out with a warning.
    """
    import yaml

    aero = key_values(args.aero, '--aero', yaml.safe_load)
    ball_params = key_values(args.ball_param, '--ball-param', float)
    spin = result.fixed.get('spin_rpm')
    wind = list(aero.get('wind') or [0.0, 0.0, 0.0])
    warnings = []
    for name, c in result.coefficients.items():
        if not c.identifiable:
            continue
        if name in AERO_NAMES:
            aero[name] = c.value
        elif name == 'c_m_alpha':
            ball_params[name] = c.value
        elif name == 'spin_rpm':
            spin = c.value
        else:
            wind['xy'.index(name[-1])] = c.value
    if any(c.identifiable for n, c in result.coefficients.items() if n.startswith('wind')):
        aero['wind'] = wind
    try:
        AeroModel.from_mapping(aero)
    except (ValueError, TypeError) as exc:
        warnings.append(f'simulate will not take the fitted aero settings ({exc}): left out')
        aero = key_values(args.aero, '--aero', yaml.safe_load)
    try:
        get_preset(result.ball, ball_params)
    except ValueError as exc:
        warnings.append(f'simulate will not take the fitted ball ({exc}): left out')
        ball_params = key_values(args.ball_param, '--ball-param', float)
    argv = ['--ball', result.ball, '--model', result.model, '--moment', result.moment]
    if spin is not None:
        argv += ['--spin-rpm', f'{spin:.6g}']
    for key, value in ball_params.items():
        argv += ['--ball-param', f'{key}={value:.6g}']
    for key, value in aero.items():
        if key == 'wind':
            argv += ['--wind', *(f'{float(v):.6g}' for v in value)]
        else:
            argv += ['--aero', f'{key}={json.dumps(value) if isinstance(value, bool) else value}'
                     if not isinstance(value, float) else f'{key}={value:.6g}']
    return argv, warnings


def print_report(report: dict[str, Any]) -> None:
    """Print the report as text: the coefficients' table, the residuals, the correlations."""
    flights = report['flights']
    print(f"football-ros fit: {len(flights)} flight(s), {sum(f['fixes'] for f in flights)} "
          f"fixes; {report['ball']} ball, {report['model']} model ({report['moment']} moment)")
    print(f"{'coefficient':<13}{'value':>12}  {'95 % interval':<26} identifiable")
    for name, c in report['coefficients'].items():
        unit = f' {c["unit"]}' if c['unit'] else ''
        if c['identifiable']:
            lo, hi = c['ci95']
            interval = f'[{lo:.5g}, {hi:.5g}]{unit}'
            how = ' (profile likelihood)' if c['interval'] == 'profile' else ''
            print(f"{name:<13}{c['value']:>12.5g}  {interval:<26} yes{how}")
        else:
            print(f"{name:<13}{'-':>12}  {'-':<26} NO: {c['reason']}")
    noise = report['noise_m']
    said = f'estimated sigma {noise:.4g} m' if noise is not None else 'sigma as given'
    print(f"residual RMS {report['residual_rms_m']:.4g} m ({said}); chi-square "
          f"{report['chi2']:.1f} on {report['dof']} degrees of freedom")
    if report['axis_noise_deg'] is not None:
        print(f"axis noise estimated: {report['axis_noise_deg']:.3g} deg")
    names = [n for n, c in report['coefficients'].items() if c['identifiable']]
    if len(names) > 1:
        print('correlation:')
        index = report['correlation']['names']
        matrix = report['correlation']['matrix']
        for a in names:
            row = ' '.join(f'{matrix[index.index(a)][index.index(b)]:+.3f}' for b in names)
            print(f'  {a:<12} {row}')
    print('simulate with: football-ros simulate ' + ' '.join(report['simulate_args']))


def write_figures(result: 'FitResult', folder: Path) -> list[Path]:
    """Write residuals.png (per flight and axis, against time) and paths.png; their paths."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    for f in result.flights:
        err = (f.fitted[:, :3] - f.fixes) * 100.0
        for j, ax in enumerate(axes):
            ax.plot(f.times, err[:, j], '.', ms=2)
    for j, ax in enumerate(axes):
        ax.set_ylabel(f'{"xyz"[j]} fit - fix [cm]')
        ax.axhline(0.0, color='k', lw=0.5)
    axes[-1].set_xlabel('time since the first fix [s]')
    fig.suptitle(f'residuals, {len(result.flights)} flight(s): RMS '
                 f'{result.residual_rms_m * 100:.2f} cm')
    paths = [folder / 'residuals.png']
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    fig, (side, top) = plt.subplots(2, 1, figsize=(9, 8))
    for f in result.flights:
        line, = side.plot(f.fitted[:, 0], f.fitted[:, 2], lw=1)
        side.plot(f.fixes[:, 0], f.fixes[:, 2], '.', ms=2, color=line.get_color())
        top.plot(f.fitted[:, 0], f.fitted[:, 1], lw=1, color=line.get_color())
        top.plot(f.fixes[:, 0], f.fixes[:, 1], '.', ms=2, color=line.get_color())
    side.set_ylabel('z [m]')
    top.set_ylabel('y [m]')
    top.set_xlabel('x [m] (field)')
    fig.suptitle('fixes (dots) and fitted paths (lines)')
    paths.append(folder / 'paths.png')
    fig.savefig(paths[-1], dpi=110)
    plt.close(fig)
    return paths
