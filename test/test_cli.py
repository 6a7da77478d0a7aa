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

"""The ``football-ros`` command-line contract (keys, header, rows, exit codes)."""

import csv
import json
import math
import subprocess
import sys

from cli_run import run_cli
from football_ros.physics import CSV_HEADER
from football_ros.programs import ros_commands
import numpy as np
import pytest
import yaml


def run(*args, check=True):
    proc = run_cli(*args)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def test_modes_json_has_the_contract_keys_and_paper_numbers():
    report = json.loads(run('modes', '--json').stdout)
    for key in (
        'm_alpha',
        'h1',
        'omega_fast',
        'omega_slow',
        'stable',
        'critical_spin_rpm',
        'equilibrium_sideslip',
        'c1',
        'c2',
    ):
        assert key in report
    assert report['stable'] is True
    assert report['omega_fast'] == pytest.approx(32.01, rel=5e-3)
    assert report['omega_slow'] == pytest.approx(5.958, rel=5e-3)
    assert report['equilibrium_sideslip'] == pytest.approx(0.0617, rel=5e-3)
    assert len(report['c1']) == 2 and len(report['c2']) == 2


def test_modes_table_is_readable():
    out = run('modes', '--ball', 'rugby').stdout
    assert 'omega_fast' in out and 'rugby' in out and 'rpm' in out


def test_simulate_writes_the_contract_csv(tmp_path):
    out = tmp_path / 'flight.csv'
    run('simulate', '--rate', '50', '--out', str(out))
    with open(out) as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == CSV_HEADER
    assert ','.join(rows[0][:18]) == (
        't,x,y,z,vx,vy,vz,qx,qy,qz,qw,sx,sy,sz,alpha,beta,alpha_linear,beta_linear'
    )
    data = np.array(rows[1:], dtype=float)
    t_land = 2 * 27.4 * math.sin(math.radians(30)) / 9.81
    assert data[-1, 0] == pytest.approx(t_land, abs=1e-9) and data[-1, 3] == 0.0
    assert np.allclose(data[:-1, 0], np.arange(len(data) - 1) / 50.0, atol=1e-12)
    assert np.all(data[:-1, 3] >= 0)
    # Unit quaternion with x axis = s; mean sideslip positive for a right-handed spiral.
    assert np.allclose(np.linalg.norm(data[:, 7:11], axis=1), 1.0, atol=1e-12)
    assert np.mean(data[:, 15]) > 0


def test_simulate_stops_at_duration(tmp_path):
    out = tmp_path / 'short.csv'
    run('simulate', '--duration', '0.5', '--rate', '10', '--ball', 'rugby', '--out', str(out))
    data = np.loadtxt(out, delimiter=',', skiprows=1)
    assert data.shape == (6, len(CSV_HEADER)) and data[-1, 0] == pytest.approx(0.5)


@pytest.mark.parametrize(
    'args',
    [
        ['modes', '--speed', '-3'],
        ['modes', '--speed', 'nan'],
        ['modes', '--speed', 'abc'],
        ['modes', '--ball', 'soccer'],
        ['modes', '--ball-param', 'mass'],
        ['modes', '--bogus'],
        ['simulate', '--out', '/nonexistent-dir/x.csv'],
        ['simulate'],
        [],
        ['simulate', '--rate', '0', '--out', 'x.csv'],
    ],
)
def test_bad_options_exit_2_with_one_line(args):
    proc = run(*args, check=False)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('football-ros: error:'), proc.stderr
    assert 'Traceback' not in proc.stderr


def test_physics_and_headless_commands_need_no_ros(tmp_path):
    """With rclpy and every ROS message package unimportable, the headless commands still run."""
    blocked = [
        'rclpy',
        'std_msgs',
        'geometry_msgs',
        'nav_msgs',
        'diagnostic_msgs',
        'visualization_msgs',
        'rosgraph_msgs',
        'std_srvs',
        'builtin_interfaces',
    ]
    csv_path, figs = tmp_path / 'f.csv', tmp_path / 'figs'
    code = (
        f'import sys\nfor name in {blocked!r}: sys.modules[name] = None\n'
        'from football_ros.cli import main\n'
        f"assert main(['modes', '--json']) == 0\n"
        f"assert main(['simulate', '--out', {str(csv_path)!r}]) == 0\n"
        f"assert main(['plot', {str(csv_path)!r}, '--out', {str(figs)!r}]) == 0\n"
        f"assert main(['montecarlo', '--n', '50', '--quiet', '--out', "
        f"{str(tmp_path / 'mc.csv')!r}]) == 0\n"
        "assert not any(m.split('.')[0] in {'rclpy'} "
        'for m in sys.modules if sys.modules[m] is not None)\n'
    )
    proc = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr
    assert len(list(figs.glob('*.png'))) == 4


HEAVY = ('numba', 'matplotlib', 'rclpy', 'llvmlite')


@pytest.mark.parametrize(
    'argv',
    [
        ['modes'],
        ['modes', '--json', '--model', 'full'],
        ['--help'],
        ['montecarlo', '--help'],
        ['simulate', '--help'],
    ],
)
def test_modes_and_help_import_neither_numba_nor_matplotlib_nor_rclpy(argv):
    """Start-up: commands that do not integrate, draw or talk to ROS import none of them."""
    code = (
        'import sys\nfrom football_ros.cli import main\n'
        f'try:\n    code = main({argv!r})\nexcept SystemExit as exc:\n    code = exc.code\n'
        'sys.stdout.flush()\n'
        f"print('HEAVY', sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
        'sys.exit(code or 0)\n'
    )
    proc = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == 'HEAVY []'
    if argv[-1] == '--help':
        assert '``' not in proc.stdout  # no raw reStructuredText in the help


def test_modes_without_numba_matches_the_flight_s_modes():
    """Modes builds its numbers without the integrator: the same as Flight's linear modes."""
    from football_ros.cli import modes_report
    from football_ros.physics import Flight, Release

    release = Release(ball='rugby', model='full', aero={'air_density': 1.1}, spin_rpm=450.0)
    report = modes_report(release)
    modes = Flight.from_release(release).modes
    assert report['omega_fast'] == modes.omega_fast and report['m_alpha'] == modes.m_alpha
    assert report['equilibrium_sideslip'] == modes.equilibrium_sideslip


def test_help_shows_defaults_and_describes_moment():
    out = ' '.join(run('montecarlo', '--help').stdout.split())
    assert '(default: 10000)' in out and '(default: american)' in out
    assert '27.4 american' in out  # the preset-dependent defaults are named
    assert 'sin2delta' in out and 'Rae & Streit' in out  # --moment has help


def test_a_closed_pipe_ends_quietly():
    """'football-ros modes | head -1': no BrokenPipeError traceback, exit code 0."""
    proc = subprocess.run(
        f'{sys.executable} -m football_ros.cli modes --ball rugby | head -1',
        shell=True,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.stdout.startswith('ball') and len(proc.stdout.splitlines()) == 1
    assert 'Traceback' not in proc.stderr and 'BrokenPipe' not in proc.stderr, proc.stderr
    code = (
        'import sys, os\nfrom football_ros.cli import main\n'
        'r, w = os.pipe()\nos.close(r)\nos.dup2(w, 1)\n'
        "sys.exit(main(['modes', '--json']))\n"
    )
    proc = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and proc.stderr == '', proc.stderr


def _read_only(cmd):
    """
    Return ``cmd`` run so that read-only folders are read-only even for root.

    Root would otherwise write through the permission bits.
    """
    import os
    import shutil

    if os.geteuid() != 0:
        return cmd
    if shutil.which('setpriv') is None:
        pytest.skip('running as root without setpriv: cannot make a folder read-only')
    return ['setpriv', '--inh-caps=-dac_override', '--bounding-set=-dac_override', *cmd]


def test_compile_ahead_into_a_per_user_cache_for_a_read_only_install(tmp_path):
    """
    A read-only package folder (a colcon install).

    The kernels go to the per-user cache chosen at import, every kernel is compiled the first
    time and loaded the second.
    """
    import os
    from pathlib import Path
    import shutil

    import football_ros

    install = tmp_path / 'install'
    shutil.copytree(
        Path(football_ros.__file__).parent,
        install / 'football_ros',
        ignore=shutil.ignore_patterns('__pycache__', '*.nbi', '*.nbc'),
    )
    home = tmp_path / 'home'
    home.mkdir()
    for folder, _dirs, files in os.walk(install):
        for name in files:
            os.chmod(os.path.join(folder, name), 0o444)
        os.chmod(folder, 0o555)
    env = {k: v for k, v in os.environ.items() if k not in ('NUMBA_CACHE_DIR', 'XDG_CACHE_HOME')}
    env.update(HOME=str(home), PYTHONPATH=str(install))
    code = (
        'import football_ros, os\n'
        'assert football_ros.__file__.startswith(%r), football_ros.__file__\n'
        "print('CACHE', os.environ.get('NUMBA_CACHE_DIR'))\n"
        'from football_ros.physics import compile_ahead\n'
        'from football_ros.physics.precompile import uncovered\n'
        'steps = compile_ahead(print)\n'
        "print('COMPILED', sum(s.compiled for s in steps),\n"
        "      'LOADED', sum(s.loaded for s in steps))\n"
        "print('UNCOVERED', uncovered())\n"
    ) % str(install)
    try:
        runs = [
            subprocess.run(
                _read_only([sys.executable, '-c', code]),
                capture_output=True,
                text=True,
                timeout=600,
                env=env,
                cwd=tmp_path,
            )
            for _ in range(2)
        ]
    finally:
        for folder, _dirs, _files in os.walk(install):
            os.chmod(folder, 0o755)
    for proc in runs:
        assert proc.returncode == 0, proc.stderr
    lines = [
        dict(
            line.split(' ', 1)
            for line in proc.stdout.splitlines()
            if line.split(' ', 1)[0] in ('CACHE', 'COMPILED', 'UNCOVERED')
        )
        for proc in runs
    ]
    cache = home / '.cache' / 'football_ros' / 'numba'
    assert lines[0]['CACHE'] == str(cache) == lines[1]['CACHE']
    assert any(cache.rglob('*.nbi')) and not any(install.rglob('*.nbi'))
    first, second = (line['COMPILED'].split() for line in lines)
    assert int(first[0]) >= 10 and lines[0]['UNCOVERED'] == '[]'  # every kernel, compiled once
    assert int(second[0]) == 0 and int(second[2]) >= 3  # ... then loaded


def test_echo_with_a_timeout_and_no_publisher_says_so_and_fails():
    """'football-ros echo TOPIC --timeout S' with nobody publishing: one line, exit code 1."""
    proc = run('echo', 'football/diagnostics_unused_topic_probe', '--timeout', '0.5', check=False)
    assert proc.returncode == 2 and 'unknown topic' in proc.stderr  # only the package's topics
    proc = run('echo', '/diagnostics', '--timeout', '0.5', check=False)
    assert proc.returncode == 1 and proc.stdout == ''
    assert proc.stderr.strip().splitlines()[-1] == (
        'football-ros echo: error: no publisher on /diagnostics within 0.5 s'
    )


def test_throw_waits_for_the_release_node_then_prints_its_answer(start_node):
    """
    A fresh 'throw' next to running nodes: matched, sent, answered, in that order, once.

    The answer is the release node's for this request id, with the vacuum-parabola flight of
    the pass (torque-only model: the centre flies the parabola), 2 V sin(theta) / g and
    V cos(theta) t.
    """
    start_node('simulator')
    start_node('release')
    proc = run(
        'throw', '--verbose', '--id', 'first-throw', '--speed', '20', '--elevation-deg', '40'
    )
    answer = yaml.safe_load(proc.stdout)
    assert answer['name'] == 'first-throw' and answer['level'] == 0
    values = {kv['key']: kv['value'] for kv in answer['values']}
    theta = math.radians(40)
    flight = 2 * 20 * math.sin(theta) / 9.81
    assert float(values['time_of_flight']) == pytest.approx(flight, rel=1e-9)
    assert float(values['range']) == pytest.approx(20 * math.cos(theta) * flight, rel=1e-9)
    steps = [line.split(']: ', 1)[1] for line in proc.stderr.splitlines() if ']: ' in line]
    assert steps == [
        'looking for the release node',
        'matched the release node',
        "request 'first-throw' sent",
        "answer to 'first-throw' received",
    ]


def test_throw_without_a_release_node_names_the_topic_and_fails():
    proc = run('throw', '--timeout', '0.5', check=False)
    assert proc.returncode == 1 and proc.stdout == ''
    assert proc.stderr.strip().splitlines()[-1] == (
        'football-ros throw: error: no release node is listening on /football/release/request'
    )


@pytest.mark.parametrize('command', list(ros_commands()))
def test_node_command_help_has_no_raw_backticks(command):
    proc = run(command, '--help')
    assert '``' not in proc.stdout and proc.stdout.strip()


def test_fast_csv_writer_matches_printf_rounding_and_reads_back(tmp_path):
    """The numba CSV writer prints what '%.6f' prints (integers as integers, nan/inf named)."""
    from football_ros.tools.fastcsv import write_csv

    rng = np.random.default_rng(5)
    values = np.concatenate(
        [
            rng.normal(0, 1e3, 20000),
            rng.normal(0, 1e-5, 2000),
            [0.0, -0.0, 0.5e-6, -0.5e-6, 1.5, 99999.9999995, np.nan, np.inf, -np.inf, 9.99e11],
        ]
    )
    flags = (np.arange(values.size) % 2).astype(np.int8)
    write_csv(tmp_path / 't.csv', {'v': values, 'flag': flags}, decimals=6)
    lines = (tmp_path / 't.csv').read_text().splitlines()
    assert lines[0] == 'v,flag' and len(lines) == values.size + 1
    differ = 0
    for line, value, flag in zip(lines[1:], values, flags):
        text, flag_text = line.split(',')
        expected = '%.6f' % value
        expected = expected if expected != '-0.000000' else '0.000000'
        if text != expected:  # a value (nearly) half-way between two 6-decimal numbers
            differ += 1
            assert abs(float(text) - value) <= 5e-7 + 4e-16 * abs(value), (value, text)
        assert flag_text == str(flag)
    assert differ <= 3
    big = {'v': np.array([1e13, 1.0])}  # beyond the fast path: full-precision fallback
    write_csv(tmp_path / 'b.csv', big)
    assert (tmp_path / 'b.csv').read_text().splitlines()[1:] == ['10000000000000', '1']


@pytest.mark.parametrize(
    'args, message',
    [
        (['throw', '--id', ''], "'id' must be 1 to 128 printable characters"),
        (['throw', '--id', 'x' * 200], "'id' must be 1 to 128 printable characters"),
        (['throw', '--id', 'req-3'], 'must not have the form req-<n>'),
        (['throw', '--timeout', '0'], '--timeout must be > 0 s'),
        (['demo', '--rate', '0'], '--rate must be in [1, 2000] Hz, got 0'),
        (['demo', '--rate', 'nan'], '--rate must be in [1, 2000] Hz, got nan'),
        (['demo', '--out', '.'], 'exists already'),
    ],
)
def test_ros_commands_check_their_options_before_starting_anything(args, message):
    proc = run(*args, check=False)  # the usage error, not a later one after starting ROS
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert 'Traceback' not in proc.stderr and proc.stdout == ''


def test_modes_prints_the_flown_wind_full_model_and_rate_based_flag():
    out = run(
        'modes', '--model', 'full', '--aero', 'c_m_p_alpha=0.036', '--wind', '-10', '0', '0'
    ).stdout
    assert 'air speed V = |v - wind|' in out and '36.405' in out
    assert 'full model at release' in out and 'equilibrium beta' in out
    report = json.loads(
        run('modes', '--model', 'full', '--aero', 'c_m_p_alpha=0.036', '--json').stdout
    )
    assert report['dynamically_stable'] is True and report['mccoy_dynamically_stable'] is False
    assert report['fast_damping_rate'] < 0 and report['slow_damping_rate'] < 0
    assert report['full']['omega_fast'] == pytest.approx(32.0077, abs=1e-3)


@pytest.mark.parametrize('ball, form', [('rugby', 'C_M = 0.0735 sin 2 delta'),
                                        ('american', 'C_M = 0.165 sin 2 delta')])
def test_the_range_warning_names_the_balls_own_moment_form(tmp_path, ball, form):
    proc = run('simulate', '--ball', ball, '--spin-rpm', '100', '--moment', 'sin2delta',
               '--out', str(tmp_path / 'f.csv'))
    [warning] = [line for line in proc.stderr.splitlines() if 'beyond the 50 deg' in line]
    assert form in warning
