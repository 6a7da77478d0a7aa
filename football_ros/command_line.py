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
Command-line pieces shared by every command (no ROS).

The release options, one-line usage errors and the help format. ``cli.py`` and the node commands
(``throw``, ``demo``) use them.
"""

from __future__ import annotations

import argparse

from .physics import PRESETS, Release
from .physics.release import MODELS, MOMENT_CURVES


class UsageError(Exception):
    """A bad command line; reported as one line and exit code 2."""


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """
    Help with each option's default and descriptions as written.

    The default is shown when it has a meaningful one; paragraphs are kept.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ''
        default = action.default
        if (
            '%(default)' in text
            or default is None
            or default is False
            or default == []
            or default is argparse.SUPPRESS
            or not action.option_strings
        ):
            return text
        return f'{text} (default: %(default)s)'


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line (UsageError) and whose help shows defaults."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault('formatter_class', HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # one line, no usage block
        raise UsageError(message)


def plain(text: str | None) -> str:
    """Return a docstring as terminal text: reStructuredText ``literals`` lose their backticks."""
    return (text or '').lstrip('\n').replace('``', '').replace(':func:', '').replace(':mod:', '')


def add_release_options(parser: argparse.ArgumentParser) -> None:
    """Add the release options shared by every command that throws a ball."""
    g = parser.add_argument_group("release (defaults: the preset's nominal release)")
    g.add_argument('--ball', default='american', help=f'preset: {", ".join(PRESETS)}')
    g.add_argument(
        '--speed',
        type=float,
        help="release speed [m/s] (default: the preset's, "
        + ', '.join(f'{p.speed:g} {n}' for n, p in PRESETS.items())
        + ')',
    )
    g.add_argument(
        '--elevation-deg',
        type=float,
        help='elevation above the horizontal [deg] '
        "(default: the preset's, "
        + ', '.join(f'{p.elevation_deg:g} {n}' for n, p in PRESETS.items())
        + ')',
    )
    g.add_argument(
        '--azimuth-deg',
        type=float,
        default=0.0,
        help='direction, counter-clockwise from +x (downfield) [deg]',
    )
    g.add_argument(
        '--spin-rpm',
        type=float,
        help='spin [rev/min], > 0 right-handed spiral '
        "(default: the preset's, "
        + ', '.join(f'{p.spin_rpm:g} {n}' for n, p in PRESETS.items())
        + ')',
    )
    g.add_argument('--alpha0-deg', type=float, default=0.0, help='initial angle of attack [deg]')
    g.add_argument('--beta0-deg', type=float, default=0.0, help='initial sideslip [deg]')
    g.add_argument(
        '--alpha-rate-deg-s',
        type=float,
        default=0.0,
        help='axis pitch rate relative to the field [deg/s]',
    )
    g.add_argument(
        '--beta-rate-deg-s',
        type=float,
        default=0.0,
        help='axis yaw rate relative to the field [deg/s]',
    )
    g.add_argument(
        '--position',
        type=float,
        nargs=3,
        default=(0.0, 0.0, 0.0),
        metavar=('X', 'Y', 'Z'),
        help='release point in field [m]',
    )
    g.add_argument(
        '--ball-param',
        action='append',
        default=[],
        metavar='KEY=VALUE',
        help='override a preset parameter, e.g. c_m_alpha=0.3 (repeatable)',
    )
    g.add_argument(
        '--model',
        default='paper',
        choices=MODELS,
        help='paper: torque only; full: + drag, lift, Magnus, damping, wind',
    )
    g.add_argument(
        '--moment',
        default='linear',
        choices=MOMENT_CURVES,
        help='overturning moment against the total angle delta: linear = C_Malpha '
        'sin(delta) (the paper), sin2delta = (C_Malpha / 2) sin(2 delta) '
        "(Rae & Streit's wind-tunnel shape)",
    )
    g.add_argument(
        '--aero',
        action='append',
        default=[],
        metavar='KEY=VALUE',
        help='full-model setting, e.g. drag=false, c_l_alpha=0.3, air_density=1.1 (repeatable)',
    )
    g.add_argument(
        '--wind',
        type=float,
        nargs=3,
        metavar=('X', 'Y', 'Z'),
        help='wind in field [m/s] (full model)',
    )


def key_values(items: list[str], option: str, convert) -> dict:
    """KEY=VALUE command-line items as a dict, each VALUE through ``convert``."""
    import yaml

    out = {}
    for item in items:
        key, sep, value = item.partition('=')
        if not sep:
            raise UsageError(f"{option} expects KEY=VALUE, got '{item}'")
        try:
            out[key.strip()] = convert(value)
        except (ValueError, yaml.YAMLError):
            raise UsageError(f"{option} {key}: cannot read '{value}'") from None
    return out


def release_from_args(args: argparse.Namespace) -> Release:
    """Build a validated :class:`Release` from parsed options (raises ReleaseError/UsageError)."""
    import yaml

    aero = key_values(args.aero, '--aero', yaml.safe_load)
    if args.wind is not None:
        aero['wind'] = list(args.wind)
    return Release(
        ball=args.ball,
        speed=args.speed,
        elevation_deg=args.elevation_deg,
        azimuth_deg=args.azimuth_deg,
        spin_rpm=args.spin_rpm,
        alpha0_deg=args.alpha0_deg,
        beta0_deg=args.beta0_deg,
        alpha_rate_deg_s=args.alpha_rate_deg_s,
        beta_rate_deg_s=args.beta_rate_deg_s,
        position=tuple(args.position),
        model=args.model,
        moment=args.moment,
        ball_params=key_values(args.ball_param, '--ball-param', float),
        aero=aero,
    )
