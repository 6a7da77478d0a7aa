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
Build the message packages in pip_ros/ with colcon into a venv of pip-installed ROS 2 Jazzy.

tf2_msgs, simulation_interfaces (1.5.1, the Jazzy branch's interface files) and vision_msgs
(4.1.1, Detection2DArray and what it holds) have no wheel.

Only for the pip ROS (scripts/setup.sh runs it): a real Jazzy install has these packages.
The ROS wheels' CMake config files name the Python include directories of the machine that
built them; those that do not exist here are pointed at this Python's before the build. The
packages are installed into the venv prefix itself (libraries in .venv/lib, which the wheels'
bootstrap puts on LD_LIBRARY_PATH; Python modules in site-packages; share/ and the ament
index beside the wheels'), so they work like the wheels' own message packages.

    python pip_ros/build_into_venv.py        (with the venv's python; idempotent)
"""

from __future__ import annotations

import os
from pathlib import Path
import re
import shutil
import subprocess
import sys
import sysconfig

HERE = Path(__file__).resolve().parent
# Built in this order; each only needs the wheels' packages.
PACKAGES = ('tf2_msgs', 'simulation_interfaces', 'vision_msgs')
_INCLUDES = re.compile(r'(INTERFACE_INCLUDE_DIRECTORIES\s+")([^"]*)(")')


def patch_cmake_configs(prefix: Path) -> list[Path]:
    """Point missing Python / numpy include directories in the wheels' CMake files at ours."""
    import numpy

    python_include = sysconfig.get_paths()['include']
    numpy_include = numpy.get_include()

    def fix(path: str) -> str:
        if not path.startswith('/') or os.path.exists(path):
            return path
        if re.search(r'/include/python3\.\d+$', path):
            return python_include
        if re.search(r'/numpy/(_core|core)/include$', path):
            return numpy_include
        return path

    changed = []
    for config in sorted(prefix.glob('share/*/cmake/*.cmake')):
        text = config.read_text()
        new = _INCLUDES.sub(
            lambda m: m[1] + ';'.join(fix(p) for p in m[2].split(';')) + m[3], text
        )
        if new != text:
            config.write_text(new)
            changed.append(config)
    return changed


def built(prefix: Path, package: str) -> bool:
    """Tell whether the package is installed from this very package.xml and imports."""
    installed = prefix / 'share' / package / 'package.xml'
    if (
        not installed.exists()
        or installed.read_bytes() != (HERE / package / 'package.xml').read_bytes()
    ):
        return False
    probe = subprocess.run([sys.executable, '-c', f'import {package}.msg'], capture_output=True)
    return probe.returncode == 0


def build(prefix: Path, package: str) -> None:
    colcon = shutil.which('colcon', path=str(prefix / 'bin'))
    if colcon is None:
        raise SystemExit(
            'colcon is not installed in the venv (pip install colcon-common-extensions)'
        )
    env = dict(
        os.environ,
        AMENT_PREFIX_PATH=str(prefix),
        CMAKE_PREFIX_PATH=str(prefix),
        PATH=f'{prefix / "bin"}{os.pathsep}{os.environ.get("PATH", "")}',
    )
    work = prefix / 'pip_ros_build'
    log = work / f'{package}.log'
    work.mkdir(exist_ok=True)
    with open(log, 'w') as out:
        proc = subprocess.run(
            [
                colcon,
                '--log-base',
                str(work / 'log'),
                'build',
                '--base-paths',
                str(HERE / package),
                '--build-base',
                str(work / 'build'),
                '--install-base',
                str(prefix),
                '--merge-install',
                '--event-handlers',
                'console_cohesion+',
                '--cmake-args',
                '-DBUILD_TESTING=OFF',
                f'-DPython3_EXECUTABLE={sys.executable}',
            ],
            cwd=work,
            env=env,
            stdout=out,
            stderr=subprocess.STDOUT,
        )
    if proc.returncode != 0:
        sys.stderr.write(log.read_text()[-4000:])
        raise SystemExit(f'colcon build of {package} failed; full log: {log}')


def main() -> int:
    prefix = Path(sys.prefix)
    for package in PACKAGES:
        if built(prefix, package):
            continue
        patch_cmake_configs(prefix)
        build(prefix, package)
        print(f'[setup] built {package} into {prefix} (pip ROS only)')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
