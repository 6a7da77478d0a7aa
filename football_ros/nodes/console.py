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
``football-ros echo`` and ``football-ros throw``.

Topic echo and a one-line pass for machines without the ``ros2`` command (pip-installed ROS). Same
output style as ``ros2 topic echo``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import Sequence

import yaml

from .dds import use_package_profile
from ..command_line import add_release_options, HelpFormatter, release_from_args, UsageError
from ..physics import ReleaseError
from ..requests import check_id


def wait_for_answer(rclpy, node, answers: list, request_id: str, deadline: float):
    """
    Spin ``node`` until ``answers`` holds the response named ``request_id``.

    Stops when the monotonic ``deadline`` passes; returns that response or None.
    """
    while True:
        answer = next((a for a in answers if a.name == request_id), None)
        if answer is not None or time.monotonic() >= deadline:
            return answer
        rclpy.spin_once(node, timeout_sec=0.05)


MATCH_SETTLE_S = 0.3
"""After our side has matched a remote endpoint, the time its side needs to match ours (DDS
discovery is two-way; data sent before the remote reader knows our writer is dropped)."""


def settle_matching(rclpy, node, seconds: float = MATCH_SETTLE_S) -> None:
    """Spin ``node`` for ``seconds`` so that endpoints matched on our side match on theirs."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)


def _init(node_name: str):
    import rclpy

    use_package_profile()  # before the participant exists
    rclpy.init()
    return rclpy, rclpy.create_node(node_name)


def echo(argv: Sequence[str] | None = None) -> int:
    from . import messages as mb
    from .topics import known_names, lookup, TOPICS

    parser = argparse.ArgumentParser(
        prog='football-ros echo',
        description='Print messages of a topic as YAML.',
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument(
        'topic',
        help=f'one of: {", ".join(known_names())} (relative names resolve to /...)',
    )
    parser.add_argument('--count', type=int, default=0, help='exit after N messages (0 = never)')
    parser.add_argument(
        '--timeout',
        type=float,
        default=0.0,
        help='exit after S seconds (0 = never); no message by then: exit code 1',
    )
    args = parser.parse_args(argv)
    topic = args.topic if args.topic in TOPICS else args.topic.lstrip('/')
    found = lookup(topic)
    if found is None:
        print(
            f'football-ros echo: error: unknown topic {args.topic[:200]!r} (known: '
            f'{", ".join(known_names())})',
            file=sys.stderr,
        )
        return 2
    msg_type, profile = found
    rclpy, node = _init('football_echo')
    seen = [0]

    def show(msg) -> None:
        print(yaml.safe_dump(mb.to_plain(msg), sort_keys=False, width=120).rstrip())
        print('---', flush=True)
        seen[0] += 1

    node.create_subscription(msg_type, topic, show, profile)
    end = time.monotonic() + args.timeout if args.timeout > 0 else float('inf')
    publishers = 0
    try:
        while rclpy.ok() and time.monotonic() < end and not (args.count and seen[0] >= args.count):
            rclpy.spin_once(node, timeout_sec=0.1)
        publishers = node.count_publishers(node.resolve_topic_name(topic))
    except KeyboardInterrupt:
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    if args.timeout > 0 and seen[0] == 0:
        name = topic if topic.startswith('/') else f'/{topic}'
        why = 'no publisher' if publishers == 0 else f'no message from {publishers} publisher(s)'
        print(
            f'football-ros echo: error: {why} on {name} within {args.timeout:g} s', file=sys.stderr
        )
        return 1
    if args.count and seen[0] < args.count:
        print(
            f'football-ros echo: error: {seen[0]} of {args.count} messages within '
            f'{args.timeout:g} s',
            file=sys.stderr,
        )
        return 1
    return 0


def throw(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog='football-ros throw',
        formatter_class=HelpFormatter,
        description='send one release request and print the answer',
    )
    add_release_options(parser)
    parser.add_argument(
        '--id',
        help='correlation id (default: throw-<8 random hex digits>, which no other client uses)',
    )
    parser.add_argument(
        '--timeout', type=float, default=10.0, help='seconds to wait for the answer'
    )
    parser.add_argument(
        '--verbose',
        action='store_true',
        help='log each step (looking, matched, sent, answered) with its time on stderr',
    )
    try:
        args = parser.parse_args(argv)
        args.id = f'throw-{os.urandom(4).hex()}' if args.id is None else args.id
        request = dict(release_from_args(args).to_mapping(), id=check_id(args.id))
        if not args.timeout > 0.0:
            raise UsageError(f'--timeout must be > 0 s, got {args.timeout:g}')
    except (UsageError, ReleaseError, ValueError) as exc:
        print(f'football-ros throw: error: {exc}', file=sys.stderr)
        return 2
    from diagnostic_msgs.msg import DiagnosticStatus
    from std_msgs.msg import String

    from . import qos

    rclpy, node = _init('football_throw')

    def step(text: str) -> None:
        if args.verbose:
            node.get_logger().info(text)

    step('looking for the release node')
    answers = []
    # The answer's way first: our request writer is created only once our reader has matched
    # the release node's response writer, so the release node learns of our reader in the first
    # endpoint exchange, before our writer exists: normally long before any request reaches it
    # (an answer sent before that would be lost). The request needs no waiting (formerly a
    # fixed 0.3 s): it is reliable and our writer has matched their reader, so a copy that
    # arrives before their reader knows our writer is sent again once it does.
    responses = node.create_subscription(
        DiagnosticStatus, qos.RELEASE_RESPONSE, answers.append, qos.REQUEST
    )
    end = time.monotonic() + args.timeout
    # Imported while discovery runs (in Fast DDS's threads): geometry_msgs and numpy take about
    # 0.1 s that throw would otherwise spend before its participant exists.
    from . import messages as mb

    pub = None
    try:
        while time.monotonic() < end and (pub is None or pub.get_subscription_count() == 0):
            if pub is None and responses.get_publisher_count() > 0:
                pub = node.create_publisher(String, qos.RELEASE_REQUEST, qos.REQUEST_WRITER)
                continue
            rclpy.spin_once(node, timeout_sec=0.01)
        if pub is None or pub.get_subscription_count() == 0:
            print(
                'football-ros throw: error: no release node is listening on '
                f'{node.resolve_topic_name(qos.RELEASE_REQUEST)}',
                file=sys.stderr,
            )
            return 1
        step('matched the release node')
        pub.publish(String(data=json.dumps(request)))
        step(f"request '{args.id}' sent")
        answer = wait_for_answer(rclpy, node, answers, args.id, end)
        if answer is None:
            print(
                f'football-ros throw: error: no answer within {args.timeout:g} s', file=sys.stderr
            )
            return 1
        step(f"answer to '{args.id}' received")
        print(yaml.safe_dump(mb.to_plain(answer), sort_keys=False, width=120).rstrip())
        return 0 if mb.level_of(answer) != 'ERROR' else 1
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
