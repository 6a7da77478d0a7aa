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

"""The physics package's imports: no circle, aero.py on presets alone, modes without numba."""

import ast
from pathlib import Path
import subprocess
import sys

PHYSICS = Path(__file__).resolve().parents[1] / 'football_ros' / 'physics'


def _graph() -> dict[str, set[str]]:
    """Return module -> the sibling modules it imports (relative imports, anywhere in it)."""
    graph = {}
    for path in PHYSICS.glob('*.py'):
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                if node.module:
                    deps.add(node.module.split('.')[0])
                else:
                    deps |= {a.name for a in node.names}
        graph[path.stem] = deps & {p.stem for p in PHYSICS.glob('*.py')} - {path.stem}
    return graph


def test_physics_has_no_import_circle():
    graph = _graph()
    done, stack = set(), []

    def visit(name):
        assert name not in stack, 'import circle: ' + ' -> '.join(stack + [name])
        if name in done:
            return
        stack.append(name)
        for dep in sorted(graph[name]):
            visit(dep)
        stack.pop()
        done.add(name)

    for name in sorted(graph):
        visit(name)


def test_aero_imports_only_presets_and_stability_lives_with_the_modes():
    graph = _graph()
    assert graph['aero'] == {'presets'}
    assert 'aero' not in graph['presets'] and 'modes' not in graph['linear_theory']
    source = (PHYSICS / 'aero.py').read_text()
    assert 'def dynamic_stability' not in source
    assert 'def dynamic_stability' in (PHYSICS / 'modes.py').read_text()


def test_modes_report_loads_no_numba():
    code = (
        'import sys; from football_ros.physics.modes import modes_report; '
        'from football_ros.physics import Release; '
        "modes_report(Release(model='full')); print('numba' in sys.modules)"
    )
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == 'False'
