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

"""bench/results.py: a benchmark's section of RESULTS.md is replaced whole."""

import importlib.util
import os
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / 'bench'


def _results(tmp_path):
    spec = importlib.util.spec_from_file_location('results', BENCH / 'results.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.RESULTS = tmp_path / 'RESULTS.md'
    return module


def test_a_rerun_replaces_its_whole_section_even_with_headings_in_its_output(tmp_path):
    results = _results(tmp_path)
    results.write_section('planner', '## Accuracy\nold 1\n## Wobble\nold 2', 'cmd')
    results.write_section('other', 'other body', 'cmd2')
    results.write_section('planner', '## Accuracy\nnew 1\n## Wobble\nnew 2', 'cmd')
    text = results.RESULTS.read_text()
    assert 'old' not in text and text.count('## Accuracy') == 1 and 'new 2' in text
    assert text.count('## planner') == 1 and 'other body' in text
    assert text.index('## planner') < text.index('## other')  # the section kept its place
    assert '```\n\n## other' in text and '\n\n\n' not in text  # one blank line between


def test_a_section_names_the_commit_its_run_started_from(tmp_path):
    results = _results(tmp_path)
    results._commit = lambda: 'b2'  # the checkout when the section is written
    results.write_section('same', 'body', 'cmd', 'b2')
    results.write_section('moved', 'body', 'cmd', 'a1')
    text = results.RESULTS.read_text()
    assert 'commit b2, 2 cores' in text.replace(f'{os.cpu_count()} cores', '2 cores')
    assert 'commit a1, b2 when recorded,' in text
