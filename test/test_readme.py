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
The README and the pages it sends a reader to: short, its commands real, its links alive.

Every topic of the topic table is in msg_docs/README.md: test/test_topics.py checks that
(``test_every_topic_has_a_page_naming_its_type``); here only that the README points there.
"""

import argparse
from pathlib import Path
import re

REPO = Path(__file__).resolve().parents[1]
README = REPO / 'README.md'
MAX_LINES = 200
LINK = re.compile(r'\]\(([^)\s]+)\)')


def _readme() -> str:
    return README.read_text(encoding='utf-8')


def _code_lines(text: str) -> list[str]:
    """Return the README's indented code lines, stripped."""
    return [line.strip() for line in text.splitlines() if line.startswith('    ') and line.strip()]


def _slug(heading: str) -> str:
    """Return the anchor GitHub gives a heading: lower case, no punctuation, hyphens."""
    text = re.sub(r'[^\w\- ]', '', heading.strip().lower())
    return text.replace(' ', '-')


def _broken_links(page: Path) -> list[str]:
    text = page.read_text(encoding='utf-8')
    anchors = {_slug(m.group(1)) for m in re.finditer(r'^#+\s+(.*)$', text, re.M)}
    broken = []
    for target in LINK.findall(text):
        if re.match(r'[a-z]+:', target):  # https:, mailto:, ...
            continue
        path, _, anchor = target.partition('#')
        if not path:
            if anchor not in anchors:
                broken.append(target)
            continue
        if not (page.parent / path).exists():
            broken.append(target)
    return broken


def test_readme_is_at_most_200_lines():
    lines = _readme().splitlines()
    assert len(lines) <= MAX_LINES, f'README.md has {len(lines)} lines (at most {MAX_LINES})'


def test_the_two_setup_commands_and_ci():
    text = _readme()
    scripts = [line for line in _code_lines(text) if line.startswith('bash scripts/')]
    assert set(scripts) == {'bash scripts/demo.sh', 'bash scripts/test.sh'}, scripts
    quick = text.split('## Quick start', 1)[1].split('\n## ', 1)[0]
    assert scripts[0] == 'bash scripts/demo.sh'
    assert quick.index('bash scripts/demo.sh') < quick.index('bash scripts/test.sh')
    ci = (REPO / '.ci' / 'run').read_text(encoding='utf-8')
    assert 'bash scripts/test.sh' in [line.strip() for line in ci.splitlines()]


def _commands() -> set[str]:
    from football_ros.cli import build_parser
    from football_ros.programs import ros_commands

    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return set(sub.choices) | set(ros_commands())


def test_every_command_is_in_the_command_reference():
    reference = (REPO / 'docs' / 'commands.md').read_text(encoding='utf-8')
    commands = _commands()
    assert {'simulate', 'plot', 'modes', 'simulator', 'throw', 'plan', 'planner'} <= commands
    missing = sorted(c for c in commands if not re.search(rf'football-ros {c}\b', reference))
    assert not missing, f'docs/commands.md does not list: {missing}'
    assert 'docs/commands.md' in LINK.findall(_readme())


def test_readme_points_to_the_topic_table():
    # The table itself is checked against football_ros.nodes.topics.TOPICS by test_topics.py.
    assert 'msg_docs/README.md' in LINK.findall(_readme())
    assert '| `football/pose` |' not in _readme(), 'the topic table lives in msg_docs alone'


def test_every_relative_link_of_the_readme_exists():
    assert not _broken_links(README)


def test_every_relative_link_of_the_docs_exists():
    pages = sorted((REPO / 'docs').glob('*.md')) + [REPO / 'msg_docs' / 'README.md',
                                                    REPO / 'msg_docs' / 'simulation_interfaces.md']
    broken = {page.name: _broken_links(page) for page in pages}
    assert not {k: v for k, v in broken.items() if v}


def test_no_machine_paths_in_readme_and_docs():
    for page in [README, *sorted((REPO / 'docs').glob('*.md'))]:
        assert '/work/' not in page.read_text(encoding='utf-8'), page.name
