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

"""Shared fixtures: an isolated ROS domain, node subprocesses ended by PID, a message collector."""

from __future__ import annotations

import os
from pathlib import Path
import signal
import subprocess
import sys
import threading
import time

from hypothesis import settings
import pytest

# Property tests draw the same examples on every run (derandomize: seeded by each test), so that
# a fresh clone's run is the run that passed here; FOOTBALL_ROS_HYPOTHESIS=explore draws new
# ones (a fuzz campaign; what it finds goes back as an @example).
settings.register_profile('suite', derandomize=True)
settings.register_profile('explore', derandomize=False)
settings.load_profile(os.environ.get('FOOTBALL_ROS_HYPOTHESIS', 'suite'))

# One ROS domain for this test session: FOOTBALL_ROS_TEST_DOMAIN if set (parallel checkouts give
# each its own), else chosen from the PID so that parallel runs do not meet; discovery stays on
# this machine. Set before rclpy is initialised anywhere in this process.
os.environ['ROS_DOMAIN_ID'] = os.environ.get('FOOTBALL_ROS_TEST_DOMAIN') or str(
    100 + os.getpid() % 100
)
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('RCUTILS_LOGGING_BUFFERED_STREAM', '1')

REPO = Path(__file__).resolve().parents[1]


class NodeProcess:
    """A football_ros node in a subprocess; ``stop()`` ends exactly that process by PID."""

    def __init__(self, command: str, *args: str, log_dir: Path) -> None:
        self.log_path = log_dir / f'{command}-{time.monotonic_ns()}.log'
        self._log = open(self.log_path, 'w')
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', command, *args],
            stdout=self._log,
            stderr=subprocess.STDOUT,
            env=dict(os.environ),
        )
        self.pid = self.proc.pid

    def stop(self, sig: int = signal.SIGINT, timeout: float = 10.0) -> int:
        if self.proc.poll() is None:
            os.kill(self.pid, sig)
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.kill(self.pid, signal.SIGKILL)
                self.proc.wait()
        self._log.close()
        return self.proc.returncode

    def log(self) -> str:
        if not self._log.closed:
            self._log.flush()
        return self.log_path.read_text()

    def wait_for_log(self, text: str, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.log():
                return
            if self.proc.poll() is not None:
                raise AssertionError(f'node exited ({self.proc.returncode}):\n{self.log()}')
            time.sleep(0.05)
        raise AssertionError(f"'{text}' not logged in {timeout} s:\n{self.log()}")


@pytest.fixture
def start_node(tmp_path):
    """Start a node: ('simulator', '--ros-args', ...) -> NodeProcess, waited until ready."""
    started: list[NodeProcess] = []

    def _start(command: str, *args: str, ready: str = 'ready') -> NodeProcess:
        node = NodeProcess(command, *args, log_dir=tmp_path)
        started.append(node)
        if ready:
            node.wait_for_log(ready)
        return node

    yield _start
    for node in started:
        node.stop()


class Collector:
    """An rclpy node spun in a background thread that records what it subscribes to."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(f'test_collector_{os.getpid()}', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.messages: dict[str, list] = {}
        self.arrivals: dict[str, list[int]] = {}
        self.lost: dict[str, int] = {}  # messages DDS reports lost to a subscription
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while self.context.ok():
            try:
                self.executor.spin_once(timeout_sec=0.05)
            except Exception:
                if not self.context.ok():
                    return
                raise

    def subscribe(self, msg_type, topic: str, qos, raw: bool = False) -> None:
        """
        Record messages of ``topic`` (``raw``: serialized bytes, cheaper at high rates).

        And count the messages DDS reports lost to this reader (``lost[topic]``).
        """
        from rclpy.event_handler import SubscriptionEventCallbacks

        with self._lock:
            self.messages.setdefault(topic, [])
            self.arrivals.setdefault(topic, [])
            self.lost.setdefault(topic, 0)

        def callback(msg, topic=topic):
            now = time.monotonic_ns()
            with self._lock:
                self.messages[topic].append(msg)
                self.arrivals[topic].append(now)

        def lost(info, topic=topic):
            with self._lock:
                self.lost[topic] += info.total_count_change

        self.node.create_subscription(
            msg_type, topic, callback, qos, raw=raw,
            event_callbacks=SubscriptionEventCallbacks(message_lost=lost),
        )

    def publisher(self, msg_type, topic: str, qos):
        return self.node.create_publisher(msg_type, topic, qos)

    def get(self, topic: str) -> list:
        with self._lock:
            return list(self.messages[topic])

    def clear(self) -> None:
        with self._lock:
            for topic in self.messages:
                self.messages[topic].clear()
                self.arrivals[topic].clear()

    def wait_for(self, predicate, timeout: float = 20.0, what: str = 'condition') -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate():
                return
            time.sleep(0.02)
        raise AssertionError(f'timed out after {timeout} s waiting for {what}')

    def wait_for_subscribers(self, publisher, count: int = 1, timeout: float = 20.0) -> None:
        self.wait_for(lambda: publisher.get_subscription_count() >= count, timeout, 'a subscriber')

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.context.try_shutdown()
        self._thread.join(timeout=2.0)


@pytest.fixture
def collector():
    c = Collector()
    yield c
    c.close()


@pytest.fixture(scope='session')
def prediction_bound():
    """Return bench/prediction_bound.py as a module (its flights, priors and global bound)."""
    import importlib

    bench = str(REPO / 'bench')
    sys.path.insert(0, bench)  # it imports prediction_benchmark and results from its folder
    try:
        return importlib.import_module('prediction_bound')
    finally:
        sys.path.remove(bench)
