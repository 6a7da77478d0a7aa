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

"""Node start-up and shutdown (nodes/runner.py): repeated signals at any moment, --help."""

import os
import signal
import subprocess
import sys
import time

from football_ros.nodes import qos
from football_ros.physics import Release
from geometry_msgs.msg import PoseStamped
import pytest
from rosutil import order_flight


def _spawn(command, *args):
    return subprocess.Popen(
        [sys.executable, '-m', 'football_ros.cli', command, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=dict(os.environ),
    )


def _wait_for_signal_handlers(proc, timeout=120.0):
    """
    Wait until the process catches SIGTERM (SigCgt in /proc): the package installed its handlers.

    Python catches SIGINT from its own start; a SIGINT before the package's handlers, while the
    interpreter itself starts, meets Python's default one (KeyboardInterrupt, exit -2).
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        for line in open(f'/proc/{proc.pid}/status'):
            caught = int(line.split()[1], 16) if line.startswith('SigCgt:') else 0
            if caught & (1 << (signal.SIGTERM - 1)):
                return
        time.sleep(0.005)
    raise AssertionError('the program never installed its signal handlers')


def _two_sigints(proc, gap=0.02):
    os.kill(proc.pid, signal.SIGINT)
    time.sleep(gap)
    if proc.poll() is None:
        os.kill(proc.pid, signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        os.kill(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        raise AssertionError(f'did not exit after two SIGINTs:\n{out}')
    return proc.returncode, out


# Delays after the spawn cover the interpreter start, the imports, rclpy.init, the node's
# construction and its warm-up (the simulator is ready after about 1-2 s here).
@pytest.mark.parametrize('command', ['simulator', 'release', 'tracker'])
@pytest.mark.parametrize('delay', [0.1, 0.3, 0.6, 0.9, 1.2, 1.6])
def test_two_sigints_during_start_up_exit_cleanly(command, delay):
    proc = _spawn(command)
    _wait_for_signal_handlers(proc)  # the program's first lines ran (a busy machine: seconds)
    time.sleep(delay)
    code, out = _two_sigints(proc)
    assert code == 0, out
    assert 'Traceback' not in out, out


@pytest.mark.parametrize('gap', [0.0, 0.005, 0.05, 0.3])
def test_two_sigints_mid_flight_and_during_clean_up(start_node, collector, gap):
    node = start_node('simulator', '--ros-args', '-p', 'publish_rate:=1000.0')
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    order_flight(collector, Release(), f'sig-{gap}')
    collector.wait_for(lambda: len(collector.get(qos.POSE)) > 50, 10.0, 'poses')
    os.kill(node.pid, signal.SIGINT)
    time.sleep(gap)  # the second one lands while the node is stopping its pacer / destroying
    if node.proc.poll() is None:
        os.kill(node.pid, signal.SIGINT)
    node.proc.wait(timeout=20)
    assert node.stop() == 0
    assert 'Traceback' not in node.log(), node.log()


def test_release_node_two_sigints_when_ready(start_node):
    node = start_node('release')
    os.kill(node.pid, signal.SIGINT)
    os.kill(node.pid, signal.SIGINT)
    node.proc.wait(timeout=20)
    assert node.stop() == 0 and 'Traceback' not in node.log(), node.log()


@pytest.mark.parametrize('program', ['simulator', 'release'])
def test_help_prints_parameters_and_exits_without_starting(program):
    proc = subprocess.run(
        [sys.executable, '-m', f'football_ros.nodes.{program}', '--help'],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0 and 'usage:' in proc.stdout
    assert 'ready' not in proc.stdout + proc.stderr  # the node never started
    if program == 'simulator':
        assert 'publish_rate (default 100.0 [1 .. 2000])' in proc.stdout
        assert 'trail_length (default 500 [0 .. 100000])' in proc.stdout


def test_a_stop_signal_in_llvmlites_callbacks_waits_for_a_safe_point():
    """The first signal is not raised inside code C calls back; the retry raises it outside."""
    from football_ros.nodes import runner

    scope = {'__name__': 'llvmlite.binding.executionengine', 'sys': sys}
    exec('def callback():\n    return sys._getframe()', scope)  # a frame of llvmlite's
    unsafe, safe = scope['callback'](), sys._getframe()
    assert runner.in_unsafe_code(unsafe) and not runner.in_unsafe_code(safe)
    signals = runner._Signals()
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGALRM)}
    signals.install()
    try:
        signals._handle(signal.SIGINT, unsafe)  # deferred: no exception, a retry armed
        assert signals.stop and signals.deferred == 1
        assert signal.getitimer(signal.ITIMER_REAL)[0] > 0.0
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signals._handle(signal.SIGINT, safe)  # a second signal: only counted
        assert signals.received == 2
        with pytest.raises(runner._Shutdown):
            signals._retry(signal.SIGALRM, safe)  # out of llvmlite: raised once
        signals._retry(signal.SIGALRM, safe)  # nothing pending any more
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def test_make_executor_gives_the_kind_asked_and_falls_back_with_a_warning(monkeypatch):
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from football_ros.nodes.runner import make_executor

    class Logger:

        lines = []

        def warning(self, text):
            self.lines.append(text)

    class Node:

        def get_logger(self):
            return Logger()

    rclpy.init()
    try:
        events = make_executor('events', Node())
        assert not isinstance(events, SingleThreadedExecutor) and hasattr(events, 'wake')
        assert isinstance(make_executor('single_threaded', Node()), SingleThreadedExecutor)
        assert Logger.lines == []
        monkeypatch.setitem(sys.modules, 'rclpy.experimental', None)  # an rclpy without it
        assert isinstance(make_executor('events', Node()), SingleThreadedExecutor)
        assert len(Logger.lines) == 1 and 'no EventsExecutor' in Logger.lines[0]
    finally:
        rclpy.shutdown()
