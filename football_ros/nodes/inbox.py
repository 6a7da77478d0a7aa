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
The request readers' view of what DDS lost before the node could read it.

A reliable reader is told (``message_lost``) of samples its writer gave up on (a writer's
KEEP_LAST history that overwrote unacknowledged requests) or that were dropped on the way; the
node cannot answer those (their ids are unknown), so it counts them and says so.
"""

from __future__ import annotations

from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node

from .logs import throttled


def lost_counter(node: Node, counts: dict, what: str) -> SubscriptionEventCallbacks:
    """
    Return event callbacks that add lost samples to ``counts['lost']`` and log them.

    The warning names the count and the remedy, at most once a second.
    """

    def lost(info) -> None:
        counts['lost'] += int(info.total_count_change)
        throttled(
            node.get_logger(), 'warning',
            f"{counts['lost']} {what} lost before this node could read them (DDS); a client "
            'that must not lose any publishes with a KEEP_ALL history (msg_docs: release_request)',
            1.0,
        )

    return SubscriptionEventCallbacks(message_lost=lost)
