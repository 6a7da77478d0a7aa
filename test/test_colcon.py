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

"""The repo is a proper ament_python package: colcon builds it on the pip-installed ROS."""

import json
import os
from pathlib import Path
import shutil
import subprocess
import sys

from football_ros.programs import CLI_SCRIPT, NODES
import pytest

REPO = Path(__file__).resolve().parents[1]
VENV = Path(sys.prefix)


@pytest.mark.skipif(
    shutil.which('colcon', path=str(VENV / 'bin')) is None, reason='colcon not installed'
)
def test_colcon_build_installs_node_executables(tmp_path):
    env = dict(
        os.environ, AMENT_PREFIX_PATH=str(VENV), PATH=f'{VENV / "bin"}:{os.environ["PATH"]}'
    )
    proc = subprocess.run(
        [
            str(VENV / 'bin' / 'colcon'),
            'build',
            '--base-paths',
            str(REPO),
            '--build-base',
            str(tmp_path / 'build'),
            '--install-base',
            str(tmp_path / 'install'),
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lib = tmp_path / 'install' / 'football_ros' / 'lib' / 'football_ros'
    for exe in (*NODES, CLI_SCRIPT):  # every node and the command (ros2 run football_ros ...)
        assert os.access(lib / exe, os.X_OK), f'{exe} missing from {lib}'
    share = tmp_path / 'install' / 'football_ros' / 'share'
    assert (share / 'ament_index' / 'resource_index' / 'packages' / 'football_ros').exists()
    assert (share / 'football_ros' / 'package.xml').exists()
    assert (share / 'football_ros' / 'launch' / 'football.launch.py').exists()
    assert (share / 'football_ros' / 'config' / 'football.yaml').exists()
    assert (share / 'football_ros' / 'rviz' / 'football.rviz').exists()
    # The installed entry point runs from the install space, not from the source tree.
    site = next((tmp_path / 'install' / 'football_ros' / 'lib').glob('python3*/site-packages'))
    assert (site / 'football_ros' / 'nodes' / 'fastdds_profile.xml').is_file()  # nodes/dds.py
    out = subprocess.run(
        [str(lib / 'football-ros'), 'modes', '--json'],
        cwd=tmp_path,
        env=dict(env, PYTHONPATH=str(site)),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)['omega_fast'] == pytest.approx(32.01, rel=5e-3)


@pytest.mark.skipif(
    shutil.which('colcon', path=str(VENV / 'bin')) is None, reason='colcon not installed'
)
def test_colcon_test_runs_the_package_tests(tmp_path):
    """
    `colcon test` on the pip ROS.

    A cheap selection (the lint tests of the ament_python template, the RViz config and the
    launch file arguments).
    """
    env = dict(
        os.environ, AMENT_PREFIX_PATH=str(VENV), PATH=f'{VENV / "bin"}:{os.environ["PATH"]}'
    )
    colcon = str(VENV / 'bin' / 'colcon')
    paths = [
        '--base-paths',
        str(REPO),
        '--build-base',
        str(tmp_path / 'build'),
        '--install-base',
        str(tmp_path / 'install'),
    ]
    for command in (
        ['build', *paths],
        ['test', *paths, '--pytest-args', '-k', 'flake8 or pep257 or rviz or defaults'],
    ):
        proc = subprocess.run(
            [colcon, *command], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
        )
        assert proc.returncode == 0, proc.stdout + proc.stderr
    result = subprocess.run(
        [colcon, 'test-result', '--test-result-base', str(tmp_path / 'build'), '--all'],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    summary = result.stdout.strip().splitlines()[-1]
    assert summary.startswith('Summary: ') and ' 0 errors, 0 failures, 0 skipped' in summary, (
        summary
    )
    tests = int(summary.split()[1])
    assert tests >= 5, summary  # 2 lint tests, 2 RViz tests, the launch defaults
