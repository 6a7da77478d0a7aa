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
``football-ros paper --out DIR``: the paper's Figures 3-8 regenerated and its numbers checked.

Dzielski & Blackburn, Dynamics 2022, 2(1), 27-39 ("the paper"; text in the project's
shared/paper folder, CC BY 4.0). :func:`cases` are the releases of its Figures 3 to 8 as its
text describes them; :func:`plot_case` draws each in the paper's axes with the nonlinear
(integrated) flight beside the frozen linear theory (the paper's solution, eq. 12) and the
quasi-steady one. :func:`report_rows` is every number the paper prints, its value as printed,
this package's, the difference and the explanation; :func:`write_report` writes them to
``report.md`` (:func:`parse_report` reads it back). Figures are in the velocity frame: s2 the
axis component up (nose above the velocity > 0), s3 to the right (nose right > 0); the axes in
degrees are the angles themselves (:func:`angles_deg`: atan2(s2, s1), atan2(s3, s1)), not
180/pi times a direction cosine.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from pathlib import Path
import textwrap

import numpy as np

from .figures import angles_deg
from ..physics import Flight, frames, get_preset, Release
from ..physics.aero import VALIDITY
from ..physics.frames import GRAVITY
from ..physics.linear_theory import linear_modes, LinearModes, local_modes
from ..physics.release import RPM

MPH = 0.44704
"""One mile per hour [m/s]."""
FIG3_DURATION = 2.8
"""The paper's Figure 3 and 4 duration [s]."""
PRICE_TAU = 0.308
"""Price et al.'s tau (their Table 1), as the paper quotes it."""
PAPER_M_ALPHA_DASHED = 89.0
"""The paper's M_alpha [1/s^2] of the dashed curve in its Figure 4."""


@dataclass(frozen=True)
class Row:
    """
    One printed number of the paper against the package.

    ``paper`` the value as a number and ``printed`` as the paper words it ('about 3'),
    ``bounds`` what the printed value admits (its rounding, or the qualifier's range),
    ``package`` this package's value (None: a number of another model, quoted only),
    ``agrees`` whether the package's value is inside ``bounds``, ``note`` the explanation.
    """

    key: str
    quantity: str
    unit: str
    paper: float
    printed: str
    bounds: tuple[float, float]
    package: float | None
    note: str
    source: str = 'the paper'

    @property
    def agrees(self) -> bool | None:
        """Package value within the printed value's rounding (None: no package value)."""
        if self.package is None:
            return None
        return self.bounds[0] <= self.package <= self.bounds[1]

    @property
    def diff(self) -> float | None:
        """Return package - paper (None without a package value)."""
        return None if self.package is None else self.package - self.paper

    @property
    def rel_diff(self) -> float | None:
        """(package - paper) / |paper|."""
        if self.package is None or self.paper == 0:
            return None
        return (self.package - self.paper) / abs(self.paper)


def rounding(value: float, printed: str) -> tuple[float, float]:
    """Return the interval a number printed as ``printed`` (e.g. '0.0617') rounds from."""
    digits = printed.split('.')[1] if '.' in printed else ''
    half = 0.5 * 10.0 ** (-len(digits))
    return value - half, value + half


def _row(
    key, quantity, unit, printed: str, package, note, bounds=None, source='the paper', value=None
):
    """Return a :class:`Row`; ``value`` when the printed words end in no number."""
    last = printed.split()[-1]
    number = float(last) if value is None else float(value)
    return Row(
        key,
        quantity,
        unit,
        number,
        printed,
        bounds or rounding(number, last),
        None if package is None else float(package),
        note,
        source,
    )


@dataclass(frozen=True)
class Case:
    """
    A case of the paper's figures.

    name (file stem), figure (paper figure number), title, caption, release, kind: 'series'
    (s2 and s3 against time) or 'plane' (s2 against s3); extras: 'dashed_m_alpha' (Figure 4)
    or 'circles' (the slow-mode circles of Figures 5 and 8).
    """

    name: str
    figure: int
    title: str
    caption: str
    release: Release
    kind: str
    extras: tuple[str, ...] = field(default=())


def cases() -> list[Case]:
    """Return the releases of the paper's Figures 3 to 8, as its text describes them."""
    aligned = 'axis along the velocity, not rotating relative to the field'
    return [
        Case(
            'fig3_spiral_aligned_series',
            3,
            'Paper Fig. 3: spiral pass, 27.4 m/s, 30 deg, 600 rpm; ' + aligned,
            "Time series of s2 (nose up) and s3 (nose right) over the paper's 2.8 s. The "
            'paper compares its solution (here: frozen linear theory) with data digitised '
            "from Price et al.'s Figure 3 (not reproduced here).",
            Release(),
            'series',
        ),
        Case(
            'fig4_spiral_aligned_plane',
            4,
            'Paper Fig. 4: the same pass in the s2-s3 plane; dashed: M_alpha = 89 1/s^2',
            "The axis in the velocity frame. Circles: the paper's solution (frozen linear "
            "theory, M_alpha = 190.9 1/s^2); dashed: the same solution with the paper's "
            'M_alpha = 89 1/s^2, its end at 2.8 s marked by a red circle. The paper also '
            "shows Price et al.'s and Rae's data (not reproduced here).",
            Release(),
            'plane',
            ('dashed_m_alpha',),
        ),
        Case(
            'fig5_spiral_nose_up_plane',
            5,
            'Paper Fig. 5: spiral pass, nose 10 deg above the velocity, not rotating',
            "The axis in the velocity frame. Grey solid: the circle the slow mode's arrow "
            'tip traces, radius |C2| about the equilibrium s3p, as the paper describes it; '
            'dotted: the inner circle through the cusps |C2| - |C1| and the outer one |C2| + '
            '|C1| (frozen theory).',
            Release(alpha0_deg=10.0),
            'plane',
            ('circles',),
        ),
        Case(
            'fig6_spiral_yaw_rate_plane',
            6,
            'Paper Fig. 6: spiral pass, axis along the velocity, nose turning right at 30 deg/s',
            'Aligned release, not rotating about the horizontal (pitch) axis, s3 rate 30 deg/s '
            '(relative to the field, = relative to the velocity frame for this axis). The '
            'precession angle turns back on itself at times.',
            Release(beta_rate_deg_s=30.0),
            'plane',
        ),
        Case(
            'fig7_screw_kick_aligned_series',
            7,
            'Paper Fig. 7: rugby screw kick, 20 m/s, 30 deg, 300 rpm; ' + aligned,
            'Time series of s2 and s3 over the kick (about 2 s): in the frozen solution little '
            'nutation, s3 about its equilibrium of 10 deg, slightly less than one precession; '
            'the nonlinear flight drifts to larger s3 as s3p(t) grows.',
            Release(ball='rugby'),
            'series',
        ),
        Case(
            'fig8_screw_kick_nose_up_plane',
            8,
            'Paper Fig. 8: rugby screw kick, nose 10 deg above the velocity, not rotating',
            'The axis in the velocity frame; s3 exceeds 20 deg, where the small-angle theory '
            'departs from the nonlinear flight.',
            Release(ball='rugby', alpha0_deg=10.0),
            'plane',
            ('circles',),
        ),
    ]


def small_angle_constants(
    m: LinearModes, s2: float, s3: float, s2_dot: float, s3_dot: float
) -> tuple[complex, complex]:
    """
    Return the paper's eqs. (13)-(14): C1, C2 [rad] from s2, s3 [rad] and their rates [rad/s].

    With the frozen modes of ``m`` (w_f, w_s, s3p); s1 = 1 as in the paper's linearisation.
    """
    w_f, w_s, s3p = m.omega_fast, m.omega_slow, m.equilibrium_sideslip
    c1 = (s3_dot - 1j * s2_dot - w_s * s2 - 1j * w_s * (s3 - s3p)) / (w_f - w_s)
    c2 = (-s3_dot + 1j * s2_dot + w_f * s2 + 1j * w_f * (s3 - s3p)) / (w_f - w_s)
    return complex(c1), complex(c2)


def components(tr) -> np.ndarray:
    """(N,) x = s2 + i s3 of an integrated flight, in the frame of its air velocity."""
    c = frames.to_velocity_frame(tr.axes, tr.air_velocities)
    return c[:, 1] + 1j * c[:, 2]


def local_s3p(tr) -> np.ndarray:
    """(N,) the local equilibrium sideslip s3p(t) [rad] of the paper's model along a flight."""
    h1 = tr.states[:, 13]
    return local_modes(tr.ball.moment_coefficient(), tr.air_velocities, h1)[3].real


def _fly(release: Release):
    return Flight.from_release(release).simulate(rate=1000.0, duration=10.0)


def _precession_turns(tr) -> float:
    """Return the turns of the complementary part x - i s3p(t) about the local equilibrium."""
    xc = components(tr) - 1j * local_s3p(tr)
    angle = np.unwrap(np.angle(xc))
    return float(abs(angle[-1] - angle[0]) / (2 * math.pi))


def report_rows() -> list[Row]:  # noqa: C901 (one list, one row per printed number)
    """Every number the paper prints, against this package (see :class:`Row`)."""
    am = get_preset('american')
    ru = get_preset('rugby')
    nominal = Release()
    tr = _fly(nominal)
    m = linear_modes(am, nominal.initial_state())
    hz = 1.0 / (2.0 * math.pi)
    tof = float(tr.times[-1])
    w_v = abs(m.omega_v)
    pair_m = 32.01 * 5.958
    pair_h1 = 32.01 + 5.958
    g_low, g_implied, g_high = (
        s3p * pair_m * 27.4 / (math.cos(math.radians(30.0)) * pair_h1)
        for s3p in (0.06165, 0.0617, 0.06175)
    )
    rows = [
        _row(
            'american.c_m_alpha', 'C_Malpha (Rae & Streit, via the paper)', '1/rad', '0.33',
            am.c_m_alpha, 'input of the preset', source='Rae & Streit, ref. [12] of the paper',
        ),
        _row(
            'american.c_m_sin2delta', 'amplitude of C_M = A sin(2 delta)', '-', '0.165',
            am.c_m_alpha / 2.0, "the package's sin2delta moment: C_Malpha / 2 sin 2 delta",
            source='Rae & Streit, ref. [12] of the paper',
        ),
        _row(
            'american.sin2delta_range', 'largest delta of the sin(2 delta) fit', 'deg', '50',
            VALIDITY['moment_sin2delta'].max_delta_deg, 'the validity range the package warns at',
            source='Rae & Streit, ref. [12] of the paper',
        ),
        _row(
            'american.inertia_transverse', 'I_t', 'kg m^2', '0.00321', am.inertia_transverse,
            'input', source='Rae, ref. [6] (a personal communication there)',
        ),
        _row(
            'american.inertia_spin', 'I_s', 'kg m^2', '0.00194', am.inertia_spin, 'input',
            source='Rae, ref. [6] (a personal communication there)',
        ),
        _row('american.speed', 'release speed', 'm/s', '27.4', am.speed, 'input'),
        _row(
            'american.speed_mph', 'release speed in mph', 'mph', 'slightly over 60',
            am.speed / MPH, '27.4 m/s = 61.3 mph', bounds=(60.0, 62.5),
        ),
        _row('american.elevation', 'release angle', 'deg', '30', am.elevation_deg, 'input'),
        _row('american.spin', 'spin', 'rpm', '600', am.spin_rpm, 'input'),
        _row(
            'american.m_alpha', 'M_alpha at 27.4 m/s', '1/s^2', '191', m.m_alpha,
            "the paper gives neither D nor rho; the preset's D = 0.1726 m, rho = 1.225 "
            'kg/m^3 give 190.91',
        ),
        _row('american.h1', 'h1 = (I_s/I_t) p', 'rad/s', '38', m.h1, '37.973 rounds to 38'),
        _row(
            'american.omega_fast', 'fast (nutation) frequency w_f', 'rad/s', '32.01',
            m.omega_fast, 'within rounding',
        ),
        _row(
            'american.omega_slow', 'slow (precession) frequency w_s', 'rad/s', '5.958',
            m.omega_slow,
            f'w_f w_s = M_alpha: the printed pair implies M_alpha = {pair_m:.2f} (which its '
            f'191 rounds) and h1 = {pair_h1:.3f}; the preset gives M_alpha = {m.m_alpha:.2f} '
            '(also 191), so w_s is 0.1 % higher. Not a contradiction: 191 fixes w_s only to '
            'three digits',
        ),
        _row(
            'american.omega_fast_hz', 'w_f in Hz', 'Hz', 'about 5', m.omega_fast * hz,
            f'{m.omega_fast * hz:.3f} Hz', bounds=(4.5, 5.5),
        ),
        _row(
            'american.omega_slow_hz', 'w_s in Hz', 'Hz', 'about 1', m.omega_slow * hz,
            f'{m.omega_slow * hz:.3f} Hz. CONTRADICTION: the paper writes "the slow mode, '
            'w_f, has a frequency of about 1 Hertz": w_f is its symbol of the fast mode '
            '(about 5 Hz); the slow one is w_s', bounds=(0.5, 1.5),
        ),
        _row(
            'american.s3p', 'equilibrium sideslip s3p = g cos(Phi) h1 / (M_alpha V)', 'rad',
            '0.0617', m.equilibrium_sideslip, 'within rounding',
        ),
        _row(
            'american.s3p_eq15', 's3p in the rounded form of eq. (15)', 'rad', '0.06',
            m.equilibrium_sideslip, 'within rounding',
        ),
        _row(
            'american.g', 'gravity g implied by the printed s3p = g cos(Phi) h1 / (M_alpha V)',
            'm/s^2', '-', GRAVITY,
            f'the paper prints no g; its s3p 0.0617 with its own M_alpha = w_f w_s = '
            f'{pair_m:.2f}, h1 = w_f + w_s = {pair_h1:.3f}, V = 27.4 m/s and Phi = 30 deg '
            f'gives g = {g_implied:.3f} (0.06165 to 0.06175: {g_low:.3f} to {g_high:.3f}); '
            f'the package flies g = {GRAVITY} m/s^2', bounds=(g_low, g_high), value=g_implied,
        ),
        _row(
            'american.long_pass', 'duration of a long pass', 's', 'about 3', tof,
            f"the package's pass lands at its release height after {tof:.3f} s (2 V sin(Phi) "
            f"/ g = {2 * am.speed * 0.5 / GRAVITY:.3f} s: no forces in the paper's model)",
            bounds=(2.5, 3.5),
        ),
        _row(
            'american.orbits_fast', 'fast-mode orbits in about 3 s', '-', '15',
            3.0 * m.omega_fast * hz,
            f"3 s x {m.omega_fast * hz:.3f} Hz; over the flight's {tof:.3f} s: "
            f'{tof * m.omega_fast * hz:.1f}', bounds=(14.5, 15.5),
        ),
        _row(
            'american.orbits_slow', 'slow-mode orbits in about 3 s', '-', '3',
            3.0 * m.omega_slow * hz,
            f'3 s x {m.omega_slow * hz:.3f} Hz; over the flight: {tof * m.omega_slow * hz:.2f} '
            f'(frozen theory), {_precession_turns(tr):.2f} (integrated flight: the slow mode '
            'slows as the ball climbs)', bounds=(2.5, 3.5),
        ),
        _row(
            'price.omega_wob', "Price et al.'s w_wob", 'rad/s', '38', m.h1,
            'package column: h1, the fast root without the torque (M_alpha = 0), which Price '
            "et al.'s 38 equals; this model's fast frequency is 32.01",
            source='Price et al., ref. [3] of the paper, Table 1',
        ),
        _row(
            'american.wob_difference', 'w_wob against w_f', '%', 'about 20',
            100.0 * (38.0 - m.omega_fast) / m.omega_fast,
            f'(38 - w_f) / w_f = {100 * (38.0 - m.omega_fast) / m.omega_fast:.1f} % '
            f'(against w_wob: {100 * (38.0 - m.omega_fast) / 38.0:.1f} %)', bounds=(15.0, 25.0),
        ),
        _row(
            'price.omega_gyr', "Price et al.'s w_gyr", 'rad/s', '2.52', None,
            "another model's number (a constant-torque precession); the paper's reading of "
            f'its formula with the angle s3p gives |w_V| = g cos(Phi) / V = {w_v:.4f} rad/s',
            source='Price et al., ref. [3] of the paper, Table 1',
        ),
        _row(
            'american.slow_over_gyr', 'w_s / w_gyr', '-', '2.4', m.omega_slow / 2.52,
            f'{m.omega_slow:.4f} / 2.52', bounds=(2.35, 2.45),
        ),
        _row(
            'american.rate_ratio', "'about five times': x' against x when |C1| ~ |C2|", '-',
            'about five', m.omega_fast / m.omega_slow,
            'package column: w_f / w_s, the ratio of the two exponents, our reading of what '
            "sets this factor (the sentence names no formula). As written it mixes units: x' "
            'is a rate [rad/s] and x an angle [rad], so "five times" is a number only in '
            'some unit of time (here: per second)',
            bounds=(4.5, 5.5), value=5.0,
        ),
    ]
    # Figure 3 and 4: aligned, not rotating relative to the field.
    s2_dot = -m.omega_v  # the frame turns at w_V about e3: s2' = -w_V for an axis fixed in field
    pc1, pc2 = small_angle_constants(m, 0.0, 0.0, s2_dot, 0.0)
    printed_c1 = (5.958 * 0.0617 - w_v) / (32.01 - 5.958)
    rows += [
        _row(
            'fig3.c1', 'Fig. 3: |C1| (C1 = i |C1|)', 'rad', '0.002214', abs(m.c1),
            f'C1 = (w_s s3p - |w_V|) / (w_f - w_s), a small difference of 0.368 and 0.310 '
            f"rad/s: it magnifies the 0.1 % of w_s and the rounding of s3p; the paper's "
            f'printed w_f, w_s, s3p and g = 9.81 give {printed_c1:.6f}',
        ),
        _row(
            'fig3.c2', 'Fig. 3: |C2| (C2 = -i |C2|)', 'rad', '0.06339', abs(m.c2),
            'CONTRADICTION: x(0) = 0 needs C1 + C2 = -i s3p, so |C2| = |C1| + s3p = '
            f"0.002214 + 0.0617 = {0.002214 + 0.0617:.5f} with the paper's own numbers (its "
            'Fig. 5 prints 0.06394 for the same part); 0.06339 with its last two digits '
            'swapped reads 0.06393, within 3e-5 of both: likely a transposition',
        ),
        _row(
            'fig3.duration', 'Figs. 3-4: duration', 's', '2.8', tof,
            'the package flies to the landing at the release height (2.793 s)',
            bounds=(2.75, 2.85),
        ),
        _row(
            'fig4.m_alpha_dashed', 'Fig. 4: M_alpha of the dashed curve', '1/s^2', '89',
            m.m_alpha * (PRICE_TAU / 2.0) / am.c_m_alpha,
            'the paper calls 89 half the correct value, but half of its 191 is 95.5 (half '
            f"of the package's: {m.m_alpha / 2:.2f}); 89 is what its other sentence gives: "
            f"M_alpha scaled by (tau / 2) / 0.33 with Price et al.'s tau = {PRICE_TAU}, i.e. "
            f'191 x 0.154 / 0.33 = {191 * 0.154 / 0.33:.1f} (package column: the same with '
            "the package's M_alpha). The figure draws 89",
        ),
        _row(
            'price.tau', "Price et al.'s tau", '-', '0.308', None,
            'quoted; read by the paper as comparable to the moment slope 0.33',
            source='Price et al., ref. [3] of the paper, Table 1',
        ),
        _row(
            'rae.c_m_alpha', "Rae's moment slope", '1/rad', '0.33', am.c_m_alpha,
            "the preset's C_Malpha", source='Rae, ref. [6] of the paper',
        ),
    ]
    # Figure 5: nose 10 deg above the velocity, not rotating.
    up = Release(alpha0_deg=10.0)
    m5 = linear_modes(am, up.initial_state())
    s2_small = math.radians(10.0)
    sc1, sc2 = small_angle_constants(m, s2_small, 0.0, s2_dot, 0.0)
    small = (
        f"the paper linearises (s2 = 10 deg = {s2_small:.5f} rad, s1 = 1, s2' = -w_V); the "
        f"package flies the unit axis (s2 = sin 10 deg = {math.sin(s2_small):.5f}, s2' = "
        f"-w_V cos 10 deg); its frequencies in the paper's formulas give C1 = "
        f'{sc1.real:+.5f} {sc1.imag:+.6f}i, C2 = {sc2.real:+.4f} {sc2.imag:+.5f}i'
    )
    rows += [
        _row(
            'fig5.alpha0', 'Fig. 5: nose above the velocity', 'deg', '10', up.alpha0_deg, 'input'
        ),
        _row('fig5.c1_re', 'Fig. 5: Re C1', 'rad', '-0.03990', m5.c1.real, small),
        _row('fig5.c1_im', 'Fig. 5: Im C1', 'rad', '0.002214', m5.c1.imag, small),
        _row('fig5.c2_re', 'Fig. 5: Re C2', 'rad', '0.2144', m5.c2.real, small),
        _row('fig5.c2_im', 'Fig. 5: Im C2', 'rad', '-0.06394', m5.c2.imag, small),
        _row(
            'fig5.circle_centre', "Fig. 5: centre of the slow mode's circle, s3", 'rad',
            '0.063', m5.equilibrium_sideslip,
            'CONTRADICTION: by eq. (12) the slow mode circles the equilibrium i s3p, and the '
            "paper's s3p is 0.0617 (0.062 to the same two digits), not 0.063",
        ),
        _row(
            'fig6.s3_rate', 'Fig. 6: initial s3 rate', 'deg/s', '30',
            Release(beta_rate_deg_s=30.0).beta_rate_deg_s, 'input',
        ),
    ]
    rows += _rugby_rows(ru, hz)
    apex = int(np.argmax(tr.positions[:, 2]))
    k = am.moment_coefficient()
    drop = 1.0 - k * float(np.linalg.norm(tr.air_velocities[apex])) ** 2 / m.m_alpha
    full = Flight.from_release(Release(model='full')).simulate(rate=1000.0, duration=10.0)
    f_apex = int(np.argmax(full.positions[:, 2]))
    f_drop = 1.0 - (np.linalg.norm(full.air_velocities[f_apex]) / am.speed) ** 2
    rows.append(
        _row(
            'american.moment_drop_apex', 'fall of the moment from release to the apex', '%',
            '25', 100.0 * drop,
            'the paper says moment coefficient; C_Malpha is constant, it is M_alpha ~ V^2 '
            f'that falls: 1 - cos^2(30 deg) = 25 % in the torque-only model; with the full '
            f"model's drag {100 * f_drop:.1f} %",
        )
    )
    return rows + _package_rows(tr, m)


def _rugby_rows(ru, hz) -> list[Row]:
    kick = Release(ball='rugby')
    tr = _fly(kick)
    m = linear_modes(ru, kick.initial_state())
    up = _fly(Release(ball='rugby', alpha0_deg=10.0))
    pair_m = 22.1 * 2.65
    own_crit = 2.0 * math.sqrt(pair_m) / (0.0026 / 0.0033) / RPM
    x = components(tr)
    x8 = components(up)
    frozen = m.axis_components(tr.times)
    frozen8 = up.modes.axis_components(up.times)
    cube = [
        linear_modes(ru, Release(ball='rugby', speed=v).initial_state()).equilibrium_sideslip
        for v in (19.0, 21.0)
    ]
    exponent = math.log(cube[1] / cube[0]) / math.log(21.0 / 19.0)
    tof = float(tr.times[-1])
    return [
        _row(
            'rugby.c_m_alpha', 'rugby C_Malpha (converted to the cross-section)', '1/rad',
            '0.147', ru.c_m_alpha,
            'input. The paper calls it "the lift coefficient slope"; it is the slope of the '
            'overturning-moment coefficient (its symbol C_Malpha and its use in M_alpha), '
            'not of lift', source='ref. [15] of the paper',
        ),
        _row(
            'rugby.c_m_alpha_ratio', 'rugby over American C_Malpha', '-', 'less than half',
            ru.c_m_alpha / get_preset('american').c_m_alpha, '0.147 / 0.33', bounds=(0.0, 0.5),
            value=0.5,
        ),
        _row(
            'rugby.inertia_spin', 'rugby I_s (thin-walled ellipsoid)', 'kg m^2', '0.0026',
            ru.inertia_spin, 'input', source='ref. [15] of the paper',
        ),
        _row(
            'rugby.inertia_transverse', 'rugby I_t', 'kg m^2', '0.0033', ru.inertia_transverse,
            'input', source='ref. [15] of the paper',
        ),
        _row(
            'rugby.speed_low', 'screw-kick speeds, lower end', 'm/s', '15', None,
            'quoted range 15-25 m/s; the package takes 20', source='ref. [16] of the paper',
        ),
        _row(
            'rugby.speed_high', 'screw-kick speeds, upper end', 'm/s', '25', None,
            'quoted range', source='ref. [16] of the paper',
        ),
        _row(
            'rugby.spin_low', 'screw-kick spins, lower end', 'rpm', '60', None,
            'quoted range 60-600 rpm; kicks below the critical spin tumble',
            source='ref. [16] of the paper',
        ),
        _row(
            'rugby.spin_high', 'screw-kick spins, upper end', 'rpm', '600', None, 'quoted range',
            source='ref. [16] of the paper',
        ),
        _row('rugby.speed', 'rugby release speed', 'm/s', '20', ru.speed, 'input'),
        _row('rugby.spin', 'rugby spin', 'rpm', '300', ru.spin_rpm, 'input'),
        _row(
            'rugby.time_of_flight', 'rugby time of flight', 's', 'just over 2', tof,
            'to the release height', bounds=(2.0, 2.2),
        ),
        _row(
            'rugby.critical_spin', 'rugby critical spin at 20 m/s', 'rpm', 'about 131',
            m.critical_spin_rpm,
            'CONTRADICTION: its criterion h1^2 > 4 M_alpha with its own w_f w_s = M_alpha = '
            f'{pair_m:.2f} and I_t / I_s = 0.0033 / 0.0026 gives {own_crit:.1f} rpm; 131 rpm '
            f'is that divided by sqrt(2) ({own_crit / math.sqrt(2):.1f}), i.e. h1^2 > '
            '2 M_alpha', bounds=(130.5, 131.5),
        ),
        _row(
            'rugby.omega_fast', 'rugby w_f', 'rad/s', '22.1', m.omega_fast, 'within rounding',
        ),
        _row(
            'rugby.omega_slow', 'rugby w_s', 'rad/s', '2.65', m.omega_slow,
            f'the printed pair implies M_alpha = {pair_m:.2f}; the preset (D = 0.19 m, rho = '
            f'1.225 kg/m^3: the paper gives neither) has {m.m_alpha:.2f}: w_s 0.4 % higher',
        ),
        _row(
            'rugby.omega_fast_hz', 'rugby w_f in Hz', 'Hz', '3.52', m.omega_fast * hz,
            'within rounding',
        ),
        _row(
            'rugby.omega_slow_hz', 'rugby w_s in Hz', 'Hz', '0.422', m.omega_slow * hz,
            'the same 0.4 % as w_s',
        ),
        _row(
            'rugby.precession_turns', 'Fig. 7: precession turns in the kick', '-',
            'slightly less than one', tof * m.omega_slow * hz,
            f"frozen theory (the paper's solution) over the {tof:.3f} s; the integrated "
            f'flight turns {_precession_turns(tr):.2f} times: its slow mode slows with V',
            bounds=(0.75, 1.0), value=1.0,
        ),
        _row(
            'rugby.mean_s3', 'Fig. 7: average s3 (the equilibrium s3p it circles)', 'deg',
            'around 10', float(angles_deg(1j * m.equilibrium_sideslip)[1]),
            'package column: s3p at release, the centre of the frozen solution, as an angle '
            '(its mean over the 2 s, less than one orbit: '
            f'{float(np.mean(angles_deg(frozen)[1])):.1f} deg); the integrated flight averages '
            f'{float(np.mean(angles_deg(x)[1])):.1f} deg: s3p grows like 1/V^3 toward the '
            'apex, as the paper warns',
            bounds=(9.0, 11.0),
        ),
        _row(
            'rugby.fig8_alpha0', 'Fig. 8: nose above the velocity', 'deg', '10', 10.0, 'input',
        ),
        _row(
            'rugby.fig8_max_s3', 'Fig. 8: largest s3', 'deg', 'over 20',
            float(np.max(angles_deg(frozen8)[1])),
            f'frozen theory, atan2(s3, s1); the integrated flight reaches '
            f'{float(np.max(angles_deg(x8)[1])):.1f} deg', bounds=(20.0, 90.0),
        ),
        _row(
            'rugby.s3p_exponent', 's3p ~ V^n: n', '-', '-3', exponent,
            'd ln s3p / d ln V at 20 m/s, Phi fixed (M_alpha ~ V^2)',
        ),
    ]


def _package_rows(tr, m: LinearModes) -> list[Row]:
    """Numbers the paper does not print, for the prose that quotes them (paper: NaN)."""
    nl = tr.aero_angles[:, :2]

    def rms(a: np.ndarray) -> float:
        return float(np.sqrt(np.mean((a - nl) ** 2)))

    frozen, quasi = rms(tr.aero_angles_linear), rms(tr.aero_angles_quasi_steady)
    nan = (math.nan, math.nan)
    here = 'this package'
    return [
        Row(
            'package.critical_spin', 'American critical spin at 27.4 m/s', 'rpm', math.nan,
            '-', nan, m.critical_spin_rpm, 'the paper gives the criterion, not this number', here,
        ),
        Row(
            'package.rms_frozen', 'rms(frozen theory - integrated) alpha, beta, nominal pass',
            'rad', math.nan, '-', nan, frozen, "the paper's solution over the whole flight", here,
        ),
        Row(
            'package.rms_quasi_steady', 'rms(quasi-steady theory - integrated)', 'rad',
            math.nan, '-', nan, quasi, 'local M_alpha(V), w_V, s3p, phases integrated', here,
        ),
        Row(
            'package.quasi_steady_gain', 'frozen rms / quasi-steady rms', '-', math.nan, '-',
            nan, frozen / quasi, 'how much closer the quasi-steady theory tracks the pass', here,
        ),
    ]


DISAGREEMENTS = [
    '- **Rounding of the inputs.** The paper gives neither diameter nor air density; the '
    'presets choose them (American D = 0.1726 m, rugby D = 0.19 m, rho = 1.225 kg/m^3) so that '
    'M_alpha rounds to the printed 191. Its frequency pairs imply M_alpha = w_f w_s = 190.71 '
    '(American) and 58.57 (rugby): the slow frequencies differ by 0.1 % and 0.4 %.',
    '- **Small angles.** The paper linearises (s1 = 1, a 10 deg offset taken as 0.1745 rad); '
    'the package flies and reports the unit axis (s2 = sin 10 deg, its rate in the turning '
    "frame -w_V cos 10 deg): the Fig. 5 constants differ by 0.3-8 %; the paper's formulas "
    "with the package's frequencies give its numbers (rows fig5.*).",
    '- **Contradictions in the paper** (its own formulas or numbers give another value): '
    'Fig. 3 |C2| 0.06339 (0.06391 from C1 + s3p); Fig. 5 circle centre 0.063 (s3p = 0.0617); '
    'Fig. 4 "half" of M_alpha is 89 (half of 191 is 95.5); rugby critical spin 131 rpm (185.5 '
    'rpm from its criterion and its own frequencies); the torque-free frequency h1 I_t / I_s '
    '(= p, 62.8 rad/s) where its equation with M_alpha = 0 gives h1 = 38.0 rad/s; the slow '
    'mode labelled w_f beside its "about 1 Hz".',
    "- **Price et al.'s 38 and 2.52 rad/s** belong to another model: 38 is h1, the fast root "
    "without torque; the paper's reading of the 2.52 formula with the angle s3p gives |w_V| = "
    '0.31 rad/s.',
    '- **Frozen theory drifts out of phase.** With V and Phi frozen at release the slow period '
    'is 2 pi / w_s; the integrated ball precesses more slowly as it climbs (M_alpha ~ V^2 falls '
    "by the paper's 25 % by the apex). The quasi-steady theory follows it (rows package.*).",
    '- **Rugby: the linear theory breaks down** as the paper says: s3p ~ 1/V^3 and Fig. 8 '
    'reaches more than 20 deg.',
    "- **Not reproduced:** Price et al.'s and Rae's curves in Figs. 3 and 4 (data not available "
    'here).',
]


def _fmt(value: float | None, spec: str = '.6g') -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return '-'
    return format(value, spec)


def write_report(path: Path, rows: list[Row]) -> None:
    """``report.md``: the numbers table, the explained disagreements, the figures."""
    lines = [
        "# The paper's numbers against football_ros",
        '',
        'Dzielski & Blackburn, Dynamics 2022, 2(1), 27-39 (doi:10.3390/dynamics2010002). '
        "`printed` = the paper's number as it prints it (`-`: not printed, a package-only "
        "number); `paper` = that number; `package` = this package's value (`-`: a number of "
        "another model, quoted only); `diff` = package - paper; `ok` = the package's value "
        "within the printed rounding (or the qualifier's range). Regenerate: "
        '`football-ros paper --out DIR`.',
        '',
        '| key | quantity | unit | printed | paper | package | diff | ok | source | explanation |',
        '|---|---|---|---|---|---|---|---|---|---|',
    ]
    for r in rows:
        ok = {None: '-', True: 'yes', False: 'NO'}[r.agrees] if not math.isnan(r.paper) else '-'
        rel = r.rel_diff
        rel = '' if rel is None or math.isnan(rel) else f' ({100 * rel:+.2f} %)'
        cells = [
            r.key, r.quantity, r.unit, r.printed, _fmt(r.paper), _fmt(r.package),
            _fmt(r.diff, '+.4g') + rel, ok, r.source, r.note,
        ]
        lines.append('| ' + ' | '.join(cells) + ' |')
    lines += ['', '## Disagreements and their causes', '', *DISAGREEMENTS, '', '## Figures', '']
    for case in cases():
        lines.append(f'- `{case.name}.png`: {case.title}. {case.caption}')
    path.write_text('\n'.join(lines) + '\n')


def parse_report(text: str) -> dict[str, tuple[float | None, float | None]]:
    """Key -> (paper, package) from a report.md table (inverse of :func:`write_report`)."""
    out = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if len(cells) == 10 and '.' in cells[0] and not cells[0].startswith('-'):
            try:
                out[cells[0]] = tuple(None if c == '-' else float(c) for c in cells[4:6])
            except ValueError:
                continue
    return out


def _m_alpha_ball(ball, m_alpha: float, speed: float):
    """Return the ball with C_Malpha scaled so that M_alpha(speed) = ``m_alpha`` [1/s^2]."""
    k = ball.moment_coefficient() * speed**2
    return ball.with_overrides({'c_m_alpha': ball.c_m_alpha * m_alpha / k})


def _signed(value: float, sign: str = '+') -> str:
    """``value`` to 4 decimals, a rounded zero without its minus sign (no '-0.0000')."""
    return format(round(value, 4) + 0.0, f'{sign}.4f')


def plot_case(case: Case, out_dir: Path) -> Path:
    """Draw one case in the paper's axes: integrated flight, frozen and quasi-steady theory."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    flight = Flight.from_release(case.release)
    tr = flight.simulate(rate=500.0, duration=10.0)
    m = flight.modes
    fig4 = 'dashed_m_alpha' in case.extras  # the paper draws its solution as circles there
    curves = (
        (components(tr), '-', 'tab:blue', 1.6, 'nonlinear flight (integrated)'),
        (m.axis_components(tr.times), 'none' if fig4 else '--', 'tab:orange', 1.3,
         'linear theory, frozen (paper; circles)' if fig4 else 'linear theory, frozen (paper)'),
        (tr.axis_components_quasi_steady, ':', 'tab:green', 1.6, 'linear theory, quasi-steady'),
    )
    s3p = angles_deg(1j * local_s3p(tr))[1]
    s3p0 = angles_deg(1j * m.equilibrium_sideslip)[1]
    fig = plt.figure(figsize=(11.0, 7.0))
    if case.kind == 'series':
        top = fig.add_axes((0.08, 0.55, 0.60, 0.34))
        bottom = fig.add_axes((0.08, 0.20, 0.60, 0.34), sharex=top)
        for x, style, color, width, label in curves:
            up, right = angles_deg(x)
            top.plot(tr.times, up, ls=style, color=color, lw=width, label=label)
            bottom.plot(tr.times, right, ls=style, color=color, lw=width, label=label)
        bottom.plot(tr.times, s3p, color='tab:red', lw=0.8, alpha=0.7,
                    label='equilibrium s3p(t), local')
        bottom.axhline(s3p0, color='tab:red', ls='--', lw=0.6,
                       label='equilibrium s3p at release')
        top.set_ylabel('nose above the velocity,\natan2(s2, s1) [deg]')
        bottom.set_ylabel('nose right of the velocity,\natan2(s3, s1) [deg]')
        bottom.set_xlabel('time since release [s]')
        plt.setp(top.get_xticklabels(), visible=False)
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
        handles, labels = bottom.get_legend_handles_labels()
        main = top
    else:
        main = fig.add_axes((0.08, 0.20, 0.60, 0.69))
        for x, style, color, width, label in curves:
            up, right = angles_deg(x)
            marker = 'o' if style == 'none' else None
            main.plot(right, up, ls=style, color=color, lw=width, label=label,
                      marker=marker, ms=3, markevery=25)
        main.plot(s3p, np.zeros_like(s3p), color='tab:red', lw=2.0, alpha=0.5,
                  label='equilibrium s3p(t), local')
        main.plot(s3p0, 0.0, 'r*', ms=12, label='equilibrium at release')
        if fig4:
            ball = _m_alpha_ball(flight.ball, PAPER_M_ALPHA_DASHED, m.speed)
            half = linear_modes(ball, case.release.initial_state())
            t = np.linspace(0.0, FIG3_DURATION, 1401)
            up, right = angles_deg(half.axis_components(t))
            main.plot(right, up, '--', color='k', lw=1.0,
                      label=f'frozen theory, M_alpha = {PAPER_M_ALPHA_DASHED:g} 1/s^2 (dashed)')
            main.plot(right[-1], up[-1], 'o', mfc='none', mec='red', ms=9,
                      label=f'its end at {FIG3_DURATION:g} s')
        if 'circles' in case.extras:
            phase = np.exp(1j * np.linspace(0.0, 2 * math.pi, 361))
            centre = 1j * m.equilibrium_sideslip
            for radius, style, label in (
                (abs(m.c2), '-', 'slow-mode circle: radius |C2| about s3p'),
                (abs(m.c2) - abs(m.c1), ':', 'inner and outer circles: |C2| -+ |C1|'),
                (abs(m.c2) + abs(m.c1), ':', None),
            ):
                up, right = angles_deg(centre + radius * phase)
                main.plot(right, up, color='0.4', ls=style, lw=0.9, label=label)
        main.axhline(0, color='k', lw=0.5)
        main.axvline(0, color='k', lw=0.5)
        main.set_xlabel('nose right of the velocity, atan2(s3, s1) [deg]')
        main.set_ylabel('nose above the velocity, atan2(s2, s1) [deg]')
        main.set_aspect('equal', adjustable='datalim')
        main.grid(alpha=0.3)
        handles, labels = main.get_legend_handles_labels()
    fig.legend(handles, labels, loc='upper left', bbox_to_anchor=(0.71, 0.89), fontsize=8,
               frameon=False)
    main.set_title(case.title, fontsize=10, loc='left')
    facts = (
        f'M_alpha = {m.m_alpha:.1f} 1/s^2, h1 = {m.h1:.2f} rad/s, w_f = {m.omega_fast:.2f}, '
        f'w_s = {m.omega_slow:.3f} rad/s, s3p = {_signed(m.equilibrium_sideslip, "")}, '
        f'C1 = {_signed(m.c1.real)}{_signed(m.c1.imag)}i, '
        f'C2 = {_signed(m.c2.real)}{_signed(m.c2.imag)}i; '
        f'flight {tr.times[-1]:.2f} s to the release height.'
    )
    caption = f'Paper Figure {case.figure}. {case.caption} {facts}'
    fig.text(0.08, 0.03, textwrap.fill(caption, 150), fontsize=8, va='bottom')
    path = out_dir / f'{case.name}.png'
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def run(out_dir: str | Path) -> list[Path]:
    """Write every case's PNG and report.md into ``out_dir``; returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [plot_case(case, out) for case in cases()]
    report = out / 'report.md'
    write_report(report, report_rows())
    return [*paths, report]
