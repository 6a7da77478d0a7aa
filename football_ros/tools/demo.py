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


def _say(text: str) -> None:
    print(f'[demo] {text}', flush=True)


def run_demo(args: argparse.Namespace) -> int:
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import PoseStamped, Vector3Stamped
    import rclpy
    from std_msgs.msg import String

    from ..nodes import qos
    from ..nodes.console import settle_matching, wait_for_answer
    from ..nodes.messages import level_of

    release = release_from_args(args)
    run_dir = Path(
        args.out or Path('runs') / datetime.datetime.now().strftime('demo_%Y%m%d_%H%M%S')
    ).resolve()
    run_dir.mkdir(parents=True, exist_ok=False)
    bag = run_dir / 'bag'
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
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
    state = {'pose': None, 'aero': None, 'responses': [], 'landed': None}
    node.create_subscription(
        PoseStamped, qos.POSE, lambda m: state.__setitem__('pose', m), qos.STATE
    )
    node.create_subscription(
        Vector3Stamped, qos.AERO_ANGLES, lambda m: state.__setitem__('aero', m), qos.STATE
    )
    responses = node.create_subscription(
        DiagnosticStatus, qos.RELEASE_RESPONSE, state['responses'].append, qos.REQUEST
    )

    def on_diagnostics(msg):
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if values.get('event') == 'landed':
                state['landed'] = status.message

    node.create_subscription(DiagnosticArray, qos.DIAGNOSTICS, on_diagnostics, qos.DIAGNOSTICS_QOS)
    requests = node.create_publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
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
        ):
            rclpy.spin_once(node, timeout_sec=0.1)
            if time.monotonic() > deadline:
                raise RuntimeError('the nodes did not find each other within 60 s')
        settle_matching(rclpy, node)
        accepted = None
        # The release node answers every request; it says "no simulator is listening" while its
        # own discovery of the simulator is still under way: then the pass is thrown again.
        for attempt in range(1, 11):
            request = dict(release.to_mapping(), id=f'demo-pass-{attempt}')
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
        _say('     t [s]     x [m]     y [m]     z [m]  alpha [deg]  beta [deg]')
        values = {kv.key: kv.value for kv in accepted.values}
        flight_end = time.monotonic() + float(values.get('time_of_flight', 'nan')) + 10.0
        next_row = 0.0  # flight time [s] of the next table row: one row per 0.1 s of flight
        while state['landed'] is None:
            if not time.monotonic() < flight_end:  # NaN (no landing predicted) ends it too
                raise RuntimeError('no landing reported; see simulator.log')
            rclpy.spin_once(node, timeout_sec=0.01)
            pose, aero = state['pose'], state['aero']
            if pose is None or aero is None:
                continue
            t = pose.header.stamp.sec + 1e-9 * pose.header.stamp.nanosec
            t0 = state.setdefault('t0', t)
            if t - t0 >= next_row - 1e-9:
                p, a = pose.pose.position, aero.vector
                _say(
                    f'{t - t0:10.2f}{p.x:10.2f}{p.y:10.2f}{p.z:10.2f}'
                    f'{math.degrees(a.x):13.2f}{math.degrees(a.y):12.2f}'
                )
                next_row = math.floor((t - t0) / 0.1 + 1e-6) * 0.1 + 0.1
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


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog='football-ros demo', description=__doc__.strip().splitlines()[0].replace('``', '')
    )
    add_release_options(parser)
    parser.add_argument('--out', help='run folder to create (default runs/demo_<date>_<time>)')
    parser.add_argument('--rate', type=float, default=200.0, help='simulator publish rate [Hz]')
    try:
        return run_demo(parser.parse_args(argv))
    except (UsageError, ReleaseError) as exc:
        print(f'football-ros demo: error: {exc}', file=sys.stderr)
        return 2


if __name__ == '__main__':
    raise SystemExit(main())
