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
``football-ros compile`` compiles every kernel a node or command runs (football_ros.tools.compile).

On a fresh numba cache: the command compiles every kernel of the package at least once; then
the nodes' warm-ups (simulator, release, tracker, planner) and the commands' kernels, in a new
process, compile nothing: they load every version from the cache the command wrote.
"""

import os
import subprocess
import sys

AFTER = """
from football_ros.estimation.tracker import warm_up as tracker
from football_ros.nodes import planner, release, simulator  # noqa: F401 (release: compile_ahead)
from football_ros.physics import compile_ahead
from football_ros.physics.precompile import cache_counts
from football_ros.tools.compile import PLACES
from football_ros.tools.fastcsv import warm_up as csv_writer

simulator._warm_up()
compile_ahead()
planner.warm_up()
tracker()
csv_writer()
loaded, compiled = cache_counts(PLACES)
print('LOADED', loaded, 'COMPILED', compiled)
"""


def _index_files(folder) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob('*.nbi'))


FIRST = """
from football_ros.physics.precompile import uncovered
from football_ros.tools.compile import compile_all, PLACES

steps = compile_all()
print('COMPILED', sum(step.compiled for step in steps), 'UNCOVERED', *uncovered(PLACES))
"""


def _run(code: str, env: dict) -> list[str]:
    # a cold compile of every kernel takes minutes on an idle machine and far longer on a busy
    # one: the limit only stops a hung process
    proc = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, timeout=4 * 3600.0,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.split()


def test_compile_covers_every_kernel_the_nodes_warm_up(tmp_path):
    cache = tmp_path / 'numba'
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    first = _run(FIRST, env)
    assert first[0] == 'COMPILED' and int(first[1]) >= 45, first
    assert first[2:] == ['UNCOVERED'], first  # every kernel has a compiled version
    index = _index_files(cache)
    assert len(index) >= 45, index
    after = _run(AFTER, env)
    assert after[0] == 'LOADED' and int(after[1]) >= 20, after  # (callees load inside callers)
    assert after[2:] == ['COMPILED', '0'], after  # nothing new compiled ...
    assert _index_files(cache) == index  # ... and no new cache entry written
