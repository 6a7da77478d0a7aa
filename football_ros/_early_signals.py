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
Clean exit for a signal while a node program is still importing.

Before nodes/runner.py takes over, the program then ends with exit code 0 and no traceback.
Installed by the package's ``__init__`` only when the process is a node program
(``simulator``, ``release``, ``recorder`` console scripts, or ``football-ros
simulator|release|record``), never for library users.
"""

from __future__ import annotations

import os
import signal
from typing import Sequence

NODE_SCRIPTS = ('simulator', 'release', 'recorder', 'planner')
NODE_COMMANDS = ('simulator', 'release', 'record', 'planner')


NODE_MODULES = tuple(
    f'football_ros.nodes.{name}' for name in ('simulator', 'release', 'recorder', 'planner')
)


def is_node_program(argv: Sequence[str], orig_argv: Sequence[str] = ()) -> bool:
    """
    Tell whether a command line runs one of the node programs.

    ``orig_argv`` is the interpreter's own command line, which names the module of
    ``python -m``.
    """
    orig = list(orig_argv)
    if '-m' in orig[:-1]:
        i = orig.index('-m')
        module, rest = orig[i + 1], orig[i + 2:]
        return module in NODE_MODULES or (
            module == 'football_ros.cli' and bool(rest) and rest[0] in NODE_COMMANDS
        )
    if not argv:
        return False
    name = os.path.basename(argv[0])
    if name in NODE_SCRIPTS:
        return True
    return name in ('football-ros', 'cli.py') and len(argv) > 1 and argv[1] in NODE_COMMANDS


def ignore_further_signals() -> None:
    """
    Ignore SIGINT and SIGTERM from now on, also while the interpreter shuts down.

    The interpreter restores the default action (which kills with -2) only for signals that
    had a Python handler.
    """
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)


def _exit_quietly(_signum, _frame) -> None:
    ignore_further_signals()
    raise SystemExit(0)


def install() -> None:
    """SIGINT/SIGTERM end the start-up quietly (main thread only; no-op elsewhere)."""
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, _exit_quietly)
    except ValueError:  # not the main thread
        pass
