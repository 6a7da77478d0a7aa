"""Clean exit for a signal while a node program is still importing (before nodes/runner.py
takes over): the program ends with exit code 0 and no traceback. Installed by the package's
``__init__`` only when the process is a node program (``simulator``, ``release``, ``recorder``
console scripts, or ``football-ros simulator|release|record``), never for library users."""

from __future__ import annotations

import os
import signal
from typing import Sequence

NODE_SCRIPTS = ("simulator", "release", "recorder")
NODE_COMMANDS = ("simulator", "release", "record")


NODE_MODULES = tuple(f"football_ros.nodes.{name}" for name in ("simulator", "release", "recorder"))


def is_node_program(argv: Sequence[str], orig_argv: Sequence[str] = ()) -> bool:
    """True for the command lines of the node programs (``orig_argv``: the interpreter's own
    command line, which names the module of ``python -m``)."""
    orig = list(orig_argv)
    if "-m" in orig[:-1]:
        i = orig.index("-m")
        module, rest = orig[i + 1], orig[i + 2:]
        return module in NODE_MODULES or (module == "football_ros.cli" and bool(rest)
                                          and rest[0] in NODE_COMMANDS)
    if not argv:
        return False
    name = os.path.basename(argv[0])
    if name in NODE_SCRIPTS:
        return True
    return name in ("football-ros", "cli.py") and len(argv) > 1 and argv[1] in NODE_COMMANDS


def ignore_further_signals() -> None:
    """SIGINT/SIGTERM ignored from now on, also while the interpreter shuts down (it restores
    the default action, which kills with -2, only for signals that had a Python handler)."""
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
