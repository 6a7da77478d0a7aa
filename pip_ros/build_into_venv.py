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
index beside the wheels'), so they work like the wheels' own message packages. Only the
interface generators rclpy uses run (pip_ros/python_only.cmake): no C++ type support.

Progress: each package as it starts and finishes (with its elapsed time), and a heartbeat
line at least every :data:`HEARTBEAT` seconds while colcon works (the build's percentage).

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
import threading
import time

HERE = Path(__file__).resolve().parent
# The folders of pip_ros/ to build (each needs only the wheels' packages; colcon orders them).
PACKAGES = (
    'tf2_msgs',
    'simulation_interfaces',
    'vision_msgs',
)
HEARTBEAT = 20.0
"""Longest silence [s] while colcon builds."""
_PERCENT = re.compile(r'^\[\s*(\d+)%\]')
_EVENT = re.compile(r'^(Starting >>>|Finished <<<|Failed\s+<<<|Aborted\s+<<<)\s+(\S+)(.*)$')
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


def say(line: str) -> None:
    """Print one progress line at once."""
    print(f'[setup] {line}', flush=True)


def _minutes(seconds: float) -> str:
    return f'{int(seconds // 60)} min {int(seconds % 60):02d} s'


def build(prefix: Path, packages: list[str]) -> None:
    """Build ``packages`` (folders of pip_ros/) with one colcon run, talking as it goes."""
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
        PYTHONUNBUFFERED='1',
    )
    # colcon's default adds make's load limit (-l cores), which on a busy machine runs one job
    env.setdefault('MAKEFLAGS', f'-j{os.cpu_count() or 1}')
    work = prefix / 'pip_ros_build'
    log = work / 'colcon.log'
    work.mkdir(exist_ok=True)
    command = [
        colcon, '--log-base', str(work / 'log'), 'build',
        '--base-paths', *(str(HERE / p) for p in packages),
        '--build-base', str(work / 'build'),
        '--install-base', str(prefix),
        '--merge-install',
        '--event-handlers', 'console_direct+', 'console_start_end+',
        '--cmake-args', '-DBUILD_TESTING=OFF', f'-DPython3_EXECUTABLE={sys.executable}',
        f'-DCMAKE_PROJECT_INCLUDE={HERE / "python_only.cmake"}',
    ]
    state = {'last': time.monotonic(), 'percent': '', 'running': {}}
    lock = threading.Lock()
    done = threading.Event()

    def heartbeat() -> None:
        while not done.wait(1.0):
            with lock:
                now = time.monotonic()
                if now - state['last'] < HEARTBEAT:
                    continue
                state['last'] = now
                running = ', '.join(
                    f'{name} {_minutes(now - began)}' for name, began in state['running'].items()
                )
                percent = f' (make at {state["percent"]} %)' if state['percent'] else ''
                say(f'  colcon: still building {running or "..."}{percent}')

    beat = threading.Thread(target=heartbeat, daemon=True)
    start = time.monotonic()
    with open(log, 'w') as out:
        proc = subprocess.Popen(
            command, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, errors='replace',
        )
        beat.start()
        for line in proc.stdout:
            out.write(line)
            with lock:
                percent = _PERCENT.match(line)
                if percent:
                    state['percent'] = percent[1]
                event = _EVENT.match(line.strip())
                if event is None:
                    continue
                kind, name, rest = event.groups()
                now = time.monotonic()
                if kind.startswith('Starting'):
                    state['running'][name] = now
                    state['percent'] = ''
                    say(f'  colcon: building {name} ...')
                else:
                    began = state['running'].pop(name, start)
                    say(f'  colcon: {kind.split()[0].lower()} {name} in {_minutes(now - began)}')
                state['last'] = now
        proc.wait()
    done.set()
    beat.join()
    if proc.returncode != 0:
        sys.stderr.write(log.read_text()[-4000:])
        raise SystemExit(f'colcon build of {", ".join(packages)} failed; full log: {log}')
    say(f'built {", ".join(packages)} into {prefix} in {_minutes(time.monotonic() - start)} '
        '(pip ROS only)')


def main() -> int:
    """Build the packages of :data:`PACKAGES` not yet installed from these very files."""
    prefix = Path(sys.prefix)
    missing = [package for package in PACKAGES if not built(prefix, package)]
    if missing:
        patch_cmake_configs(prefix)
        say(f'building {", ".join(missing)} with colcon (the interface packages without a '
            'wheel; a few minutes the first time)')
        build(prefix, missing)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
