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
The layers of docs/architecture.md hold: imports point down, no circles, no ROS below the nodes.

Every import counts, also one inside a function (a deferred import still ties two modules).
"""

import ast
from pathlib import Path
import subprocess
import sys

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / 'football_ros'
LAYERS = (  # (module prefix, rank): a module imports only lower ranks or its own layer
    ('football_ros.programs', 0),
    ('football_ros.strict_yaml', 0),
    ('football_ros._early_signals', 1),
    ('football_ros.physics', 2),
    ('football_ros.estimation', 3),
    ('football_ros.planning', 3),
    ('football_ros.simulation', 3),
    ('football_ros.identification', 3),
    ('football_ros.requests', 4),
    ('football_ros.command_line', 4),
    ('football_ros.bagfile', 4),
    ('football_ros.playback', 4),
    ('football_ros.scene', 4),
    ('football_ros.envs', 4),
    ('football_ros.nodes', 5),
    ('football_ros.envs.sim_throw', 5),
    ('football_ros.tools', 6),
    ('football_ros.cli', 7),
)
ROOT = ('football_ros', 1.5)  # the package's __init__: numba's cache folder, early signals
ROS = ('rclpy', 'rosidl', 'rcl_interfaces', 'launch', 'ament_index_python')
"""Top-level names of ROS imports (and every *_msgs / *_srvs package) kept out of the pure
layers (rank < 5)."""


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix('').parts)
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


MODULES = {_module_name(p): p for p in PACKAGE.rglob('*.py')}


def _layer(module: str) -> tuple[str, int]:
    if module == ROOT[0]:
        return ROOT
    matches = [(p, r) for p, r in LAYERS if module == p or module.startswith(p + '.')]
    assert matches, f'{module} is in no layer: add it to docs/architecture.md and LAYERS'
    return max(matches, key=lambda m: len(m[0]))


def _imports(module: str) -> tuple[set[str], set[str]]:
    """(package modules, external top-level names) that ``module`` imports anywhere."""
    path = MODULES[module]
    package = module if path.name == '__init__.py' else module.rpartition('.')[0]
    inside, outside = set(), set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split('.')[: len(package.split('.')) - node.level + 1]
                target = '.'.join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ''
            subs = [f'{target}.{a.name}' for a in node.names]
            names = subs if node.module is None else [target] + subs
        else:
            continue
        for name in names:
            if name in MODULES:
                # A module inside a package always runs under that package's __init__.
                if name != module and not module.startswith(name + '.'):
                    inside.add(name)
            elif not name.startswith('football_ros'):
                outside.add(name.split('.')[0])
    return inside, outside


GRAPH = {module: _imports(module) for module in MODULES}


@pytest.mark.parametrize('module', sorted(MODULES))
def test_imports_point_down(module):
    prefix, rank = _layer(module)
    for target in GRAPH[module][0]:
        t_prefix, t_rank = _layer(target)
        assert t_rank < rank or t_prefix == prefix, f'{module} imports {target} (up or across)'


@pytest.mark.parametrize('module', sorted(m for m in MODULES if _layer(m)[1] < 5))
def test_no_ros_below_the_nodes(module):
    ros = {
        name
        for name in GRAPH[module][1]
        if name in ROS or name.endswith(('_msgs', '_srvs', '_interfaces'))
    }
    assert not ros, f'{module} imports {sorted(ros)}'


def test_no_import_circles():
    index, low, stack, on_stack, circles = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in GRAPH[v][0]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for module in sorted(MODULES):
        if module not in index:
            visit(module)
    assert not circles, f'import circles: {circles}'


def test_aero_stands_on_the_presets_alone_and_stability_lives_with_the_modes():
    assert GRAPH['football_ros.physics.aero'][0] == {'football_ros.physics.presets'}
    assert 'def dynamic_stability' in (PACKAGE / 'physics' / 'modes.py').read_text()


def test_modes_report_loads_no_numba():
    code = (
        'import sys; from football_ros.physics.modes import modes_report; '
        'from football_ros.physics import Release; '
        "modes_report(Release(model='full')); print('numba' in sys.modules)"
    )
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == 'False'
