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
Start-up and clean shutdown shared by every node (the Jazzy demo_nodes_py pattern).

Signals: the first SIGINT or SIGTERM at any moment (while the program imports, see
football_ros/_early_signals.py; while the node is being built or warms up; while spinning) ends
the node without a traceback and with exit code 0; from then on SIGINT and SIGTERM are ignored
(``ros2 launch`` without a terminal sends a second SIGINT while the node cleans up), so the
clean-up and the interpreter's shutdown finish; SIGKILL still ends a stuck process. The node's
``close()`` (if any) runs before the node is destroyed, so threads stop and files are flushed.
A callback that raises is logged with its traceback and the node goes on. A start-up error
(an option other than ``-h`` before ``--ros-args``, ROS arguments rcl cannot parse, a
parameter out of range, DDS security that cannot start) is one line on stderr and exit code 2.

The executor is rclpy's SingleThreadedExecutor unless the node's ``executor_type`` attribute
(a parameter) asks for 'events': rclpy.experimental.EventsExecutor, which dispatches in C++
without rebuilding a wait set in Python at every wake-up (cheaper per call: the simulator's
lock-step, bench/core_benchmark.py); where rclpy lacks it (before Jazzy's rclpy 7.1.4) the
node warns and uses the other. Either is spun by ``spin_once`` with a timeout (the 7.1.6
EventsExecutor's ``spin()`` busy-waits on a core and does not return at shutdown).

``-h``/``--help`` before ``--ros-args`` prints the node's description and parameters (the node
class's ``PARAMETERS`` table: name, default, range or choices, description) and exits 0
without starting anything.
"""

from __future__ import annotations

import signal
import sys
import traceback
from typing import Callable, Sequence

import rclpy
from rclpy._rclpy_pybind11 import RCLError
from rclpy.exceptions import InvalidParameterTypeException, ParameterException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
import rclpy.signals

from .dds import use_package_profile
from .params import accept_integers_for_floats, with_guards
from .._early_signals import ignore_further_signals
from ..command_line import plain

EXIT_USAGE = 2
EXECUTOR_TYPES = ('events', 'single_threaded')
"""The executors a node's ``executor_type`` may ask for (:func:`make_executor`)."""
SPIN_WAIT_S = 0.1
"""Longest wait of the executor: the main thread runs Python signal handlers between waits."""


class _Shutdown(BaseException):
    """Raised by the signal handler in the main thread to end start-up or spinning."""


UNSAFE_MODULES = ('llvmlite',)
"""Packages whose Python code C calls back through ctypes (numba's object cache, while numba
loads or writes its cache): an exception raised there is swallowed by ctypes and leaves the
library in a broken state (seen: "Exception ignored on calling ctypes callback", SIGSEGV)."""
RETRY_S = 0.02
"""How soon a stop deferred out of such code is tried again [s]."""


def in_unsafe_code(frame) -> bool:
    """Tell whether ``frame`` or a caller of it runs code of :data:`UNSAFE_MODULES`."""
    while frame is not None:
        module = frame.f_globals.get('__name__', '')
        if module.split('.')[0] in UNSAFE_MODULES:
            return True
        frame = frame.f_back
    return False


class _Signals:
    """
    SIGINT/SIGTERM handling.

    The first signal raises :class:`_Shutdown` (unless the node is already cleaning up), or,
    once the node spins, only asks the spin loop to stop: an exception raised inside a callback
    could cut a callback's work in two (the recorder's write of one message: stored, not yet
    counted). A signal that lands in code C calls back (:func:`in_unsafe_code`) is deferred:
    SIGALRM retries every :data:`RETRY_S` until the main thread is out of it. Later signals
    are only counted.
    """

    def __init__(self) -> None:
        self.received = 0
        self.cleaning_up = False
        self.spinning = False
        self.stop = False
        self.deferred = 0
        self._pending = 0  # the signal whose _Shutdown waits for a safe point (0: none)

    def install(self) -> None:
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self._handle)
        signal.signal(signal.SIGALRM, self._retry)

    def _handle(self, signum, frame) -> None:
        self.received += 1
        ignore_further_signals()  # a second signal must not interrupt what follows
        if not self.cleaning_up:
            self.cleaning_up = True
            self.stop = True  # the spin loop ends on it, also if it never starts spinning
            self._pending = signum
            self._retry(signal.SIGALRM, frame)

    def _retry(self, _signum, frame) -> None:
        """Raise the pending :class:`_Shutdown` now if the main thread may unwind here."""
        if not self._pending:
            return
        if self.spinning:
            self._pending = 0  # the loop ends within SPIN_WAIT_S, after the callback
            return
        if in_unsafe_code(frame):
            self.deferred += 1
            signal.setitimer(signal.ITIMER_REAL, RETRY_S)
            return
        signum, self._pending = self._pending, 0
        raise _Shutdown(signum)

    def clean_up_begins(self) -> None:
        """From here on signals are ignored (also during the interpreter's own shutdown)."""
        self.cleaning_up = True
        self._pending = 0
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        ignore_further_signals()


def print_help(factory: Callable[[], Node], program: str, out=sys.stdout) -> None:
    """Usage, the node module's description and its parameters."""
    module = sys.modules.get(getattr(factory, '__module__', ''), None)
    doc = (getattr(module, '__doc__', None) or getattr(factory, '__doc__', None) or '').strip()
    print(
        f'usage: {program} [-h] [--ros-args -p NAME:=VALUE ... | --params-file FILE]\n', file=out
    )
    if doc:
        print(plain(doc) + '\n', file=out)
    print('parameters (name, default [range, choices]: description):', file=out)
    for spec in with_guards(getattr(factory, 'PARAMETERS', ())):
        print(spec.help_line(), file=out)
    print('\ntopics, frames, units and QoS: msg_docs/ (installed in share/football_ros)', file=out)


def own_options(args: Sequence[str]) -> list[str]:
    """Return the options before ``--ros-args`` (a node takes only ``-h``/``--help``)."""
    own = list(args)
    return own[: own.index('--ros-args')] if '--ros-args' in own else own


def wants_help(args: Sequence[str]) -> bool:
    """Tell whether ``-h``/``--help`` comes before any ``--ros-args``."""
    return bool({'-h', '--help'} & set(own_options(args)))


def run_node(factory: Callable[[], Node], argv: Sequence[str] | None, program: str) -> int:
    """
    Init rclpy with ``argv`` (ROS arguments included), spin the node, shut down cleanly.

    Returns the exit code: 0 after a signal or a normal end, 2 for a start-up error.
    """
    signals = _Signals()
    signals.install()  # before anything slow: a signal from here on is a clean exit
    made: list[Node] = []
    code = 0
    try:  # _Shutdown is raised at most once (the handler sets cleaning_up), anywhere in here
        try:
            code = _start_and_spin(factory, argv, program, made, signals)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        except RCLError:
            # A signal can shut the context down between two executor iterations; rclpy then
            # fails to build the next wait set instead of raising ExternalShutdownException.
            if rclpy.ok() and not signals.received:
                raise
    except _Shutdown:
        pass
    try:
        signals.clean_up_begins()
        _clean_up(made[0] if made else None)
    except _Shutdown:  # the one signal landed just before the flag was set
        _clean_up(made[0] if made else None)
    return code


def _start_and_spin(factory, argv, program: str, made: list, signals: _Signals) -> int:
    args = [program, *(sys.argv[1:] if argv is None else argv)]
    if wants_help(args[1:]):
        try:
            print_help(factory, program)
            sys.stdout.flush()
        except BrokenPipeError:  # `simulator --help | head`: the reader left, that is fine
            import os

            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    unknown = [a for a in own_options(args[1:]) if a not in ('-h', '--help')]
    if unknown:
        signals.clean_up_begins()
        print(
            f'{program}: error: unrecognized arguments: {" ".join(unknown)[:200]} (parameters '
            'go after --ros-args: --ros-args -p NAME:=VALUE; --help lists them)',
            file=sys.stderr,
        )
        return EXIT_USAGE
    try:
        # rclpy's own signal handlers are left out: they shut the context down under the node
        # and restore the default action, so that a second signal killed the process.
        use_package_profile()  # Fast DDS reads it when the participant is created
        rclpy.init(args=args, signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
        made.append(factory())
        accept_integers_for_floats(made[0])
    except (ParameterException, InvalidParameterTypeException, ValueError) as exc:
        # A start-up error (a parameter override out of range, ...): one clear line.
        signals.clean_up_begins()
        print(f'{program}: error: {exc}', file=sys.stderr)
        return EXIT_USAGE
    except RCLError as exc:  # unparsable ROS arguments, DDS security without its keys, ...
        signals.clean_up_begins()
        print(f'{program}: error: cannot start: {_rcl_reason(exc)}', file=sys.stderr)
        return EXIT_USAGE
    signals.spinning = True  # from here a signal stops the loop (not an executor half-built)
    node = made[0]
    executor = make_executor(getattr(node, 'executor_type', 'single_threaded'), node)
    executor.add_node(node)
    while rclpy.ok() and not signals.stop:  # short waits: a signal is seen within SPIN_WAIT_S
        try:
            executor.spin_once(timeout_sec=SPIN_WAIT_S)
        except (ExternalShutdownException, RCLError):
            raise
        except Exception:  # a callback's bug must not end the node: report it and go on
            if not rclpy.ok():
                break
            node.get_logger().error(
                f'a callback failed (the node goes on):\n{traceback.format_exc()}'
            )
    if signals.stop and rclpy.ok():
        _drain(executor, node)
    return 0


def make_executor(kind: str, node: Node | None = None) -> Executor:
    """
    Return a new executor of ``kind`` (one of :data:`EXECUTOR_TYPES`).

    'events' falls back to a SingleThreadedExecutor where rclpy has no EventsExecutor, with a
    warning on ``node``'s logger.
    """
    if kind == 'events':
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError as exc:
            if node is not None:
                node.get_logger().warning(
                    f'executor_type events: this rclpy has no EventsExecutor ({exc}); '
                    'using the SingleThreadedExecutor'
                )
        else:
            return EventsExecutor()
    return SingleThreadedExecutor()


def _drain(executor, node: Node) -> None:
    """
    Take what the node's readers still hold after a stop signal, if the node asks for it.

    A node with ``drain_s`` > 0 and a ``last_activity`` (time.monotonic() of its last
    callback) is spun on until its callbacks have been quiet for 0.2 s, at most ``drain_s``
    [s]: a recorder stopped right after a flight still writes the flight's tail.
    """
    import time

    limit = float(getattr(node, 'drain_s', 0.0))
    if limit <= 0.0:
        return
    end = time.monotonic() + limit
    while rclpy.ok() and time.monotonic() < end:
        if time.monotonic() - getattr(node, 'last_activity', 0.0) > 0.2:
            return
        try:
            executor.spin_once(timeout_sec=0.02)
        except Exception:  # noqa: BLE001 - stopping anyway
            return


def _rcl_reason(exc: Exception) -> str:
    """Return the rcl error without its source location, with a hint for DDS security."""
    import os

    reason = str(exc).split(', at /')[0]
    if os.environ.get('ROS_SECURITY_ENABLE', '').lower() == 'true':
        keystore = os.environ.get('ROS_SECURITY_KEYSTORE') or '(ROS_SECURITY_KEYSTORE unset)'
        reason += (
            f'; ROS_SECURITY_ENABLE=true: is the keystore {keystore} there, with an enclave '
            'for this node (ros2 security create_enclave; README, section "Security")?'
        )
    return reason


def _clean_up(node: Node | None) -> None:
    if node is not None:
        close = getattr(node, 'close', None)
        if close is not None:
            close()
        try:
            node.destroy_node()
        except RCLError:
            pass  # the context is already gone
    rclpy.try_shutdown()
