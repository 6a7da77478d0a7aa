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
football_ros: a spinning American football or rugby ball in flight, for ROS 2 Jazzy.

``football_ros.physics`` is pure numpy/scipy/numba (no ROS); ``football_ros.nodes`` wraps it in
rclpy nodes; ``football_ros.tools`` holds the recorder, the figures and the demo.

Importing this package (every entry point does, before numba) chooses where numba keeps its
compiled kernels: beside the sources when that folder is writable, else (a read-only install,
e.g. colcon's) a per-user folder, see :func:`numba_cache_dir`.
"""

import os
import sys

from . import _early_signals

# A node program: a signal while it imports ends it with exit 0 and no traceback.
if _early_signals.is_node_program(sys.argv, getattr(sys, 'orig_argv', ())):
    _early_signals.install()

__version__ = '0.1.0'


def numba_cache_dir() -> str | None:
    """
    Return the folder numba caches this package's kernels in (None = beside the sources).

    A ``NUMBA_CACHE_DIR`` set by the user wins. Otherwise, when the package folder is not
    writable: ``$XDG_CACHE_HOME/football_ros/numba`` (default ``~/.cache``), or, if that
    cannot be created, ``<tmp>/football_ros-numba-<uid>``.
    """
    if os.environ.get('NUMBA_CACHE_DIR'):
        return os.environ['NUMBA_CACHE_DIR']
    physics = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'physics')
    pycache = os.path.join(physics, '__pycache__')
    if os.access(pycache if os.path.isdir(pycache) else physics, os.W_OK):
        return None
    base = os.environ.get('XDG_CACHE_HOME') or os.path.join(os.path.expanduser('~'), '.cache')
    candidates = [os.path.join(base, 'football_ros', 'numba')]
    import tempfile

    candidates.append(
        os.path.join(
            tempfile.gettempdir(), f'football_ros-numba-{getattr(os, "getuid", lambda: 0)()}'
        )
    )
    for path in candidates:
        try:
            os.makedirs(path, exist_ok=True)
        except OSError:
            continue
        if os.access(path, os.W_OK):
            return path
    return None  # nowhere writable: numba compiles in memory every time


def _use_numba_cache_dir() -> None:
    path = numba_cache_dir()
    if path is None or os.environ.get('NUMBA_CACHE_DIR') == path:
        return
    os.environ['NUMBA_CACHE_DIR'] = path
    config = sys.modules.get('numba.core.config')
    if config is not None:  # numba was imported first: tell it too
        config.CACHE_DIR = path


_use_numba_cache_dir()
