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
The paper's printed numbers (Dzielski & Blackburn 2022) against the package: a regression.

Every number the report says the package reproduces must stay within the printed rounding
(or the qualifier's range: 'about 3', 'over 20'); every number it says differs must keep the
value the explanation gives (the package's, and the value the paper's own formulas give).
"""

import math

from football_ros.physics import get_preset, linear_modes, Release
from football_ros.tools import paper
import pytest


@pytest.fixture(scope='module')
def rows():
    return {r.key: r for r in paper.report_rows()}


REPRODUCED = [
    'american.c_m_alpha', 'american.c_m_sin2delta', 'american.sin2delta_range',
    'american.inertia_transverse', 'american.inertia_spin', 'american.speed',
    'american.speed_mph', 'american.elevation', 'american.spin', 'american.m_alpha',
    'american.h1', 'american.omega_fast', 'american.omega_fast_hz', 'american.omega_slow_hz',
    'american.s3p', 'american.s3p_eq15', 'american.long_pass', 'american.orbits_fast',
    'american.orbits_slow', 'price.omega_wob', 'american.wob_difference',
    'american.slow_over_gyr', 'american.rate_ratio', 'fig3.duration', 'fig4.m_alpha_dashed',
    'rae.c_m_alpha', 'fig5.alpha0', 'fig6.s3_rate', 'rugby.c_m_alpha', 'rugby.c_m_alpha_ratio',
    'rugby.inertia_spin', 'rugby.inertia_transverse', 'rugby.speed', 'rugby.spin',
    'rugby.time_of_flight', 'rugby.omega_fast', 'rugby.omega_fast_hz',
    'rugby.precession_turns', 'rugby.mean_s3', 'rugby.fig8_alpha0', 'rugby.fig8_max_s3',
    'rugby.s3p_exponent', 'american.moment_drop_apex', 'american.g',
]
"""Rows whose package value is inside the printed number's rounding."""

DIFFERS = {
    # key: (package value, tolerance): the disagreement the report explains
    'american.omega_slow': (5.9643, 5e-5),  # the printed pair implies M_alpha = 190.71
    'fig3.c1': (0.0022183, 5e-8),  # small difference of two terms, w_s's 0.1 %
    'fig3.c2': (0.063892, 5e-7),  # contradiction: C1 + s3p = 0.06391
    'fig5.c1_re': (-0.039766, 5e-7),  # unit axis (sin 10 deg) against 10 deg in rad
    'fig5.c1_im': (0.0023992, 5e-8),  # s2' = -w_V cos 10 deg against -w_V
    'fig5.c2_re': (0.21341, 5e-6),
    'fig5.c2_im': (-0.064072, 5e-7),
    'fig5.circle_centre': (0.061673, 5e-7),  # contradiction: the circle is about s3p
    'rugby.critical_spin': (185.87, 5e-3),  # contradiction: its own numbers give 185.5
    'rugby.omega_slow': (2.6614, 5e-5),  # the printed pair implies M_alpha = 58.57
    'rugby.omega_slow_hz': (0.42358, 5e-6),
}


def test_every_printed_number_has_a_row_and_an_explanation(rows):
    assert set(REPRODUCED) | set(DIFFERS) <= set(rows)
    quoted = {k for k, r in rows.items() if r.package is None}
    assert quoted == {
        'price.omega_gyr', 'price.tau', 'rugby.speed_low', 'rugby.speed_high',
        'rugby.spin_low', 'rugby.spin_high',
    }
    printed = {k for k, r in rows.items() if not math.isnan(r.paper)}
    assert printed == set(REPRODUCED) | set(DIFFERS) | quoted
    assert all(r.note for r in rows.values())


@pytest.mark.parametrize('key', REPRODUCED)
def test_reproduced_numbers_stay_within_their_rounding(rows, key):
    row = rows[key]
    assert row.agrees, (key, row.printed, row.package, row.bounds)


@pytest.mark.parametrize('key', sorted(DIFFERS))
def test_explained_differences_keep_their_values(rows, key):
    value, tol = DIFFERS[key]
    assert rows[key].agrees is False
    assert rows[key].package == pytest.approx(value, abs=tol)


def test_the_paper_s_own_formulas_give_the_values_the_report_names():
    """The contradictions: the value the paper's own numbers give, computed independently."""
    # Rugby critical spin: h1_c = 2 sqrt(M_alpha), M_alpha = w_f w_s = 22.1 x 2.65.
    crit = 2 * math.sqrt(22.1 * 2.65) * 0.0033 / 0.0026 * 60 / (2 * math.pi)
    assert crit == pytest.approx(185.5, abs=0.05)
    assert crit / math.sqrt(2) == pytest.approx(131.2, abs=0.05)
    # Fig. 3: x(0) = 0, so C1 + C2 = -i s3p: |C2| = |C1| + s3p.
    assert 0.002214 + 0.0617 == pytest.approx(0.06391, abs=5e-6)
    # Fig. 4: half of 191 is 95.5; 89 is 191 x (0.308 / 2) / 0.33.
    assert 191 * 0.154 / 0.33 == pytest.approx(89.1, abs=0.05)
    # The paper's small-angle constants for Fig. 5 from eqs. (13)-(14) with its frequencies.
    m = linear_modes(get_preset('american'), Release().initial_state())
    c1, c2 = paper.small_angle_constants(m, math.radians(10.0), 0.0, -m.omega_v, 0.0)
    assert (c1.real, c1.imag) == pytest.approx((-0.03997, 0.002218), abs=5e-6)
    assert (c2.real, c2.imag) == pytest.approx((0.21450, -0.063892), abs=5e-6)


def test_report_and_figures_are_written(tmp_path, rows):
    paths = paper.run(tmp_path)
    names = sorted(p.name for p in paths)
    assert names == sorted([f'{c.name}.png' for c in paper.cases()] + ['report.md'])
    assert [c.figure for c in paper.cases()] == [3, 4, 5, 6, 7, 8]
    parsed = paper.parse_report((tmp_path / 'report.md').read_text())
    assert parsed['american.omega_fast'][0] == 32.01
    assert parsed['american.omega_fast'][1] == pytest.approx(32.0089, abs=5e-5)
    assert parsed['price.tau'] == (0.308, None)
    assert parsed['package.quasi_steady_gain'][0] is None
    for path in paths[:-1]:
        assert path.stat().st_size > 20000  # a drawn figure, not an empty canvas


def test_package_only_numbers_recomputed_independently(rows):
    """Numbers the paper gives only as formulas, recomputed from the preset inputs."""
    rpm = 2 * math.pi / 60
    k = 1.225 * math.pi * 0.1726**2 / 4 * 0.1726 * 0.33 / (2 * 0.00321)
    crit = 2 * math.sqrt(k * 27.4**2) * 0.00321 / 0.00194 / rpm
    assert rows['package.critical_spin'].package == pytest.approx(crit, rel=1e-5)
    assert rows['american.long_pass'].package == pytest.approx(2 * 27.4 * 0.5 / 9.81, rel=1e-5)
    # The quasi-steady theory tracks the nominal pass 20 times closer than the frozen one.
    assert rows['package.quasi_steady_gain'].package == pytest.approx(20.1, abs=0.5)


def test_rugby_coefficients_say_which_are_borrowed():
    """Each full-model coefficient has a source per ball; the rugby ball's borrowed ones say so."""
    from dataclasses import fields

    from football_ros.physics.aero import AeroModel
    from football_ros.physics.presets import AERO_SOURCES

    coefficients = {f.name for f in fields(AeroModel) if f.name.startswith('c_')}
    for ball in ('american', 'rugby'):
        named = {k.strip() for key in AERO_SOURCES[ball] for k in key.split(',')}
        assert coefficients | {'c_m_alpha'} == named
    for key in ('c_d0, c_d2', 'c_l_alpha', 'c_m_q', 'c_l_p'):
        assert AERO_SOURCES['rugby'][key].startswith('BORROWED')
    assert '0.147' in AERO_SOURCES['rugby']['c_m_alpha']
    assert get_preset('rugby').c_m_alpha == 0.147


def test_g_row_is_what_the_printed_s3p_implies(rows):
    # s3p = g cos(Phi) h1 / (M_alpha V) with the printed w_f, w_s (M_alpha = w_f w_s,
    # h1 = w_f + w_s), V = 27.4 m/s, Phi = 30 deg, solved for g
    g = 0.0617 * 32.01 * 5.958 * 27.4 / (math.sqrt(3.0) / 2.0 * (32.01 + 5.958))
    row = rows['american.g']
    assert row.paper == pytest.approx(g, rel=1e-12) and row.package == 9.81 and row.agrees


def test_contradictions_and_misnomers_are_rows(rows):
    assert 'CONTRADICTION' in rows['american.omega_slow_hz'].note
    assert 'w_f' in rows['american.omega_slow_hz'].note
    assert 'lift coefficient slope' in rows['rugby.c_m_alpha'].note
    assert '[rad/s]' in rows['american.rate_ratio'].note
    note = rows['fig3.c2'].note
    assert '0.06393' in note and 'two digits swapped' not in note.replace('last two', '')


@pytest.mark.parametrize('up, right', [(10.0, 0.0), (0.0, 20.0), (-7.5, 12.0), (30.0, -25.0)])
def test_figure_angles_are_angles_not_scaled_direction_cosines(up, right):
    from football_ros.tools.figures import angles_deg

    # an axis with tan(up) = s2 / s1 and tan(right) = s3 / s1, made unit
    s = [1.0, math.tan(math.radians(up)), math.tan(math.radians(right))]
    norm = math.sqrt(sum(v * v for v in s))
    got_up, got_right = angles_deg(complex(s[1], s[2]) / norm)
    assert got_up == pytest.approx(up, abs=1e-9) and got_right == pytest.approx(right, abs=1e-9)


def test_captions_print_no_negative_zero():
    assert paper._signed(-1e-6) == '+0.0000' and paper._signed(-4e-5, '') == '0.0000'
    assert paper._signed(-0.00231) == '-0.0023'
