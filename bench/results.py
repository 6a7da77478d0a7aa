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
bench/RESULTS.md: the one place of the benchmarks' figures, written by the benchmarks.

Each benchmark's ``main`` runs through :func:`recorded`, which prints as usual and then puts
what it printed into its own section of RESULTS.md (replacing that section's previous run),
with the date, the commit and the command line. Prose elsewhere points here instead of copying
numbers. ``--no-record`` (removed before the benchmark sees its arguments) leaves the file alone.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import os
from pathlib import Path
import re
import subprocess
import sys
from typing import Callable

RESULTS = Path(__file__).resolve().parent / 'RESULTS.md'
HEADER = (
    '# Benchmark results\n\n'
    'Written by the benchmarks in bench/ (each replaces its own section when run; '
    '`--no-record` leaves this file alone). Every table has its baseline measured in the same '
    'run. Machines are shared and noisy: compare ratios, not absolute times.\n'
)


class _Tee(io.TextIOBase):

    def __init__(self, stream) -> None:
        self.stream, self.buffer_text = stream, io.StringIO()

    def write(self, text: str) -> int:
        self.buffer_text.write(text)
        return self.stream.write(text)

    def flush(self) -> None:
        self.stream.flush()


def _commit() -> str:
    try:
        out = subprocess.run(
            ['git', 'describe', '--always', '--dirty'],
            cwd=RESULTS.parent,
            capture_output=True,
            text=True,
            timeout=10,
        )
        return out.stdout.strip() or 'unknown'
    except (OSError, subprocess.SubprocessError):
        return 'unknown'


def write_section(name: str, body: str, command: str, commit: str | None = None) -> None:
    """
    Replace (or add) the section ``name`` of RESULTS.md with ``body``.

    ``commit``: the code the run started from (None: the checkout's now); a checkout that
    moved on during the run is named too.
    """
    text = RESULTS.read_text() if RESULTS.exists() else HEADER
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')
    now = _commit()
    commit = now if commit is None or commit == now else f'{commit}, {now} when recorded'
    section = (
        f'## {name}\n\n`{command}` ({stamp}, commit {commit}, {os.cpu_count()} cores)\n\n'
        f'```\n{body.rstrip()}\n```\n'
    )
    # Up to the section's closing fence: a benchmark's own output may hold '## ' lines.
    pattern = re.compile(rf'^## {re.escape(name)}\n.*?^```\n.*?^```\n', re.S | re.M)
    if pattern.search(text):
        text = pattern.sub(lambda _m: section, text).rstrip() + '\n'
    else:
        text = text.rstrip() + '\n\n' + section
    RESULTS.write_text(text)


def recorded(name: str, main: Callable[[], object]) -> int:
    """Run a benchmark's ``main``, then record what it printed as section ``name``."""
    record = '--no-record' not in sys.argv
    sys.argv = [a for a in sys.argv if a != '--no-record']
    command = ' '.join(['.venv/bin/python', os.path.relpath(sys.argv[0]), *sys.argv[1:]])
    commit = _commit()  # the code the run starts from
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        code = main()
    if record:
        write_section(name, tee.buffer_text.getvalue(), command, commit)
        print(f'(recorded in {os.path.relpath(RESULTS)}, section "{name}")')
    return int(code or 0)
