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
``football-ros demo``: simulator + release node + recorder, one spiral pass, a bag and figures.

Starts the three nodes as child processes (logs in the run folder), throws the default pass (or
the one given with the release options) through ``football/release/request``, prints the ball's
progress while it flies, stops everything cleanly after the landing, then draws the figures from
the bag. Ctrl-C at any time stops the children and keeps what was recorded.
"""

from __future__ import annotations

import argparse
import collections
import datetime
import json
import math
import os
from pathlib import Path
import signal
import subprocess
import sys
import time
from typing import Sequence

from ..command_line import add_release_options, release_from_args, UsageError
from ..physics import ReleaseError


class _Child:

    def __init__(self, name: str, args: list[str], log_dir: Path) -> None:
        self.name = name
        self.log_path = log_dir / f'{name}.log'
        self._log = open(self.log_path, 'w')
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'football_ros.cli', *args],
            stdout=self._log,
            stderr=subprocess.STDOUT,
            env=dict(os.environ),
        )

    def ready(self) -> bool:
        self._log.flush()
        return 'ready' in self.log_path.read_text()

    def stop(self, timeout: float = 10.0) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()


class _Table:
    """
    The live table: one row per 0.1 s of flight time, the landing the last.

    Each row holds the pose and the angles of one tick, matched by stamp whichever arrives
    first. A row's time is the flight time: the tick's stamp less the release's stamp, which
    the first tick gives (its flight time read from the flight's own path,
    :func:`football_ros.tools.flightdata.release_stamp`), so that late or skipped ticks keep
    their times. The held landed state (the same position again) is no row. Rows wait for the
    header (:meth:`show_header`, once the release is accepted).
    """

    PERIOD = 0.1  # flight time [s] between rows
    KEEP = 2000  # ticks waiting for their other half at most

    def __init__(self, flight) -> None:
        self.flight = flight
        self.landing = flight.simulate(rate=1000.0, duration=60.0).times[-1]  # [s]
        self.positions: collections.OrderedDict = collections.OrderedDict()
        self.angles: collections.OrderedDict = collections.OrderedDict()
        self.t0: float | None = None  # the release's stamp [s]
        self.next_row = 0.0
        self.last = -math.inf  # flight time [s] of the newest tick
        self._where = None  # the newest tick's position
        self._pending: str | None = None  # the newest tick's row, if not printed
        self._early: list[str] | None = []  # rows before the header

    def show_header(self) -> None:
        """Print the header, then the rows that came before it."""
        _say('     t [s]     x [m]     y [m]     z [m]  alpha [deg]  beta [deg]')
        early, self._early = self._early, None
        for row in early:
            _say(row)

    def on_pose(self, msg) -> None:
        self._pair(_stamp_ns(msg), position=msg.pose.position)

    def on_angles(self, msg) -> None:
        self._pair(_stamp_ns(msg), angles=msg.vector)

    def _pair(self, ns: int, position=None, angles=None) -> None:
        if position is not None:
            angles = self.angles.pop(ns, None)
            if angles is None:
                _keep(self.positions, ns, position, self.KEEP)
                return
        else:
            position = self.positions.pop(ns, None)
            if position is None:
                _keep(self.angles, ns, angles, self.KEEP)
                return
        self._row(ns, position, angles)

    def _row(self, ns: int, p, a) -> None:
        import numpy as np

        from .flightdata import release_stamp

        where = (p.x, p.y, p.z)
        if where == self._where:
            return  # the held landed state
        if self.t0 is None:
            self.t0 = release_stamp(np.array([ns * 1e-9]), np.array([where]), self.flight)
        t = min(ns * 1e-9 - self.t0, self.landing)  # the landed state: at the landing time
        if t < self.last:
            return  # a late half of an older tick
        self.last, self._where = t, where
        row = (
            f'{t:10.2f}{p.x:10.2f}{p.y:10.2f}{p.z:10.2f}'
            f'{math.degrees(a.x):13.2f}{math.degrees(a.y):12.2f}'
        )
        if t >= self.next_row - 1e-9:
            self._print(row)
            self.next_row = math.floor(t / self.PERIOD + 1e-6) * self.PERIOD + self.PERIOD
            self._pending = None
        else:
            self._pending = row

    def _print(self, row: str) -> None:
        if self._early is None:
            _say(row)
        else:
            self._early.append(row)

    def finish(self) -> None:
        """Print the newest tick (the landing) if its row was not printed."""
        if self._pending is not None:
            self._print(self._pending)
            self._pending = None


def _keep(buffer: collections.OrderedDict, key: int, value, limit: int) -> None:
    buffer[key] = value
    while len(buffer) > limit:
        buffer.popitem(last=False)


def _stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def _say(text: str) -> None:
    print(f'[demo] {text}', flush=True)


def run_demo(args: argparse.Namespace) -> int:
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import PoseStamped, Vector3Stamped
    import rclpy
    from std_msgs.msg import String

    from ..nodes import qos
    from ..nodes.console import settle_matching, wait_for_answer
    from ..nodes.dds import use_package_profile
    from ..nodes.messages import level_of

    from ..physics import Flight

    release = release_from_args(args)
    run_dir = _run_dir(args)
    run_dir.mkdir(parents=True, exist_ok=False)
    bag = run_dir / 'bag'
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    use_package_profile()  # for our participant and the children's
    _say(f'run folder: {run_dir}')
    children = [
        _Child(
            'simulator', ['simulator', '--ros-args', '-p', f'publish_rate:={args.rate}'], run_dir
        ),
        _Child('release', ['release'], run_dir),
        _Child('recorder', ['record', '--out', str(bag)], run_dir),
    ]
    rclpy.init()
    node = rclpy.create_node('football_demo')
    state = {'responses': [], 'landed': None, 'time_of_flight': math.nan, 'id': None}
    table = _Table(Flight.from_release(release))
    watched = [
        node.create_subscription(PoseStamped, qos.POSE, table.on_pose, qos.STATE),
        node.create_subscription(Vector3Stamped, qos.AERO_ANGLES, table.on_angles, qos.STATE),
    ]
    responses = node.create_subscription(
        DiagnosticStatus, qos.RELEASE_RESPONSE, state['responses'].append, qos.REQUEST
    )

    def on_diagnostics(msg):
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if values.get('event') == 'landed' and values.get('flight_id') == state['id']:
                state['landed'] = status.message
                state['time_of_flight'] = float(values.get('time_of_flight', 'nan'))

    node.create_subscription(DiagnosticArray, qos.DIAGNOSTICS, on_diagnostics, qos.DIAGNOSTICS_QOS)
    requests = node.create_publisher(String, qos.RELEASE_REQUEST, qos.REQUEST_WRITER)
    code = 1
    try:
        _say('starting simulator, release node and recorder ...')
        deadline = time.monotonic() + 60.0
        while not all(c.ready() for c in children):
            rclpy.spin_once(node, timeout_sec=0.1)
            for child in children:
                if child.proc.poll() is not None:
                    raise RuntimeError(f'{child.name} exited early; see {child.log_path}')
            if time.monotonic() > deadline:
                raise RuntimeError('the nodes did not start within 60 s')
        while (
            requests.get_subscription_count() == 0
            or responses.get_publisher_count() == 0
            or node.count_subscribers(qos.POSE) < 2
            or node.count_subscribers(qos.FLIGHT_ORDER) < 1
            or any(sub.get_publisher_count() == 0 for sub in watched)  # our table's sources
        ):
            rclpy.spin_once(node, timeout_sec=0.1)
            if time.monotonic() > deadline:
                raise RuntimeError('the nodes did not find each other within 60 s')
        settle_matching(rclpy, node)
        if node.count_publishers(qos.POSE) > 1:
            _say(
                f'WARNING: {node.count_publishers(qos.POSE)} simulators publish '
                f'{node.resolve_topic_name(qos.POSE)} on ROS_DOMAIN_ID '
                f"{os.environ.get('ROS_DOMAIN_ID', '0')}: the table mixes their flights (give "
                'each demo its own ROS_DOMAIN_ID)'
            )
        token = os.urandom(4).hex()  # ids no other client on the domain uses
        accepted = None
        # The release node answers every request; it says "no simulator is listening" while its
        # own discovery of the simulator is still under way: then the pass is thrown again.
        for attempt in range(1, 11):
            request = dict(release.to_mapping(), id=f'demo-{token}-{attempt}')
            state['id'] = request['id']
            _say(f'throwing: {json.dumps(request)}')
            requests.publish(String(data=json.dumps(request)))
            answer = wait_for_answer(
                rclpy, node, state['responses'], request['id'], time.monotonic() + 10.0
            )
            if answer is None:
                raise RuntimeError('the release node did not answer within 10 s; see release.log')
            _say(f'release node: {answer.message}')
            if level_of(answer) != 'ERROR':
                accepted = answer
                break
            if 'no simulator is listening' not in answer.message:
                return 2
            time.sleep(0.5)
        if accepted is None:
            raise RuntimeError('the release node never saw the simulator')
        table.show_header()
        values = {kv.key: kv.value for kv in accepted.values}
        flight_end = time.monotonic() + float(values.get('time_of_flight', 'nan')) + 10.0
        landed_at = None
        while True:  # until the landing is reported and its tick is in the table (or 3 s)
            if state['landed'] is not None:
                landed_at = landed_at or time.monotonic()
                if (table.last >= state['time_of_flight'] - 1e-3
                        or time.monotonic() - landed_at > 3.0):
                    break
            elif not time.monotonic() < flight_end:  # NaN (no landing predicted) ends it too
                raise RuntimeError('no landing reported; see simulator.log')
            rclpy.spin_once(node, timeout_sec=0.01)
        table.finish()
        _say(state['landed'])
        code = 0
    except KeyboardInterrupt:
        _say('interrupted')
        code = 130
    except RuntimeError as exc:
        _say(f'error: {exc}')
    finally:
        for child in reversed(children):  # recorder first, so the bag holds the landing
            child.stop()
        node.destroy_node()
        rclpy.try_shutdown()
    if bag.exists() and (bag / 'metadata.yaml').exists():
        from .figures import plot_source

        _say(f'bag: {bag}')
        try:
            for path in plot_source(bag, run_dir / 'figures', release.ball):
                _say(f'figure: {path}')
        except ValueError as exc:
            _say(f'no figures: {exc}')
    _say(f'logs: {", ".join(str(c.log_path) for c in children)}')
    return code


def _run_dir(args: argparse.Namespace) -> Path:
    default = Path('runs') / datetime.datetime.now().strftime('demo_%Y%m%d_%H%M%S')
    return Path(args.out or default).resolve()


def _check(args: argparse.Namespace) -> None:
    """Refuse bad options before anything starts (UsageError naming the option)."""
    from ..nodes.simulator import SimulatorNode  # the one table of the publish rate's range

    release_from_args(args)
    [spec] = [s for s in SimulatorNode.PARAMETERS if s.name == 'publish_rate']
    lo, hi = spec.limits
    if not lo <= args.rate <= hi:  # NaN fails too
        raise UsageError(f'--rate must be in [{lo:g}, {hi:g}] Hz, got {args.rate:g}')
    run_dir = _run_dir(args)
    if run_dir.exists():
        raise UsageError(f'--out {run_dir}: exists already (the demo makes a new folder)')
    if not os.access(_existing_parent(run_dir), os.W_OK):
        raise UsageError(f'--out {run_dir}: not writable')


def _existing_parent(path: Path) -> Path:
    while not path.exists():
        path = path.parent
    return path


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog='football-ros demo', description=__doc__.strip().splitlines()[0].replace('``', '')
    )
    add_release_options(parser)
    parser.add_argument('--out', help='run folder to create (default runs/demo_<date>_<time>)')
    parser.add_argument('--rate', type=float, default=200.0, help='simulator publish rate [Hz]')
    try:
        args = parser.parse_args(argv)
        _check(args)
        return run_demo(args)
    except (UsageError, ReleaseError) as exc:
        print(f'football-ros demo: error: {exc}', file=sys.stderr)
        return 2


if __name__ == '__main__':
    raise SystemExit(main())
