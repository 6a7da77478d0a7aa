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
A node whose publishers and subscriptions carry no QoS-event handlers unless given some.

rclpy gives every publisher and subscription created with default arguments its QoS-event
handlers (incompatible QoS, incompatible type, matched, ...), each a waitable of the node, and
the executor walks every waitable at every wake-up, in Python: a node with many topics pays
for them on every message, service call and timer (the simulator's dozen publishers alone
added as much to each service call and SimulateSteps goal as a do-nothing server costs,
bench/core_benchmark.py's floor). An incompatible QoS is still reported by
the other side's handler (rclpy's publishers and subscriptions elsewhere keep theirs).
"""

from __future__ import annotations

from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node


class QuietNode(Node):
    """A :class:`rclpy.node.Node` whose publishers and subscriptions skip the default handlers."""

    def create_publisher(self, *args, **kwargs):
        """Create a publisher without rclpy's default QoS-event handlers (unless given others)."""
        kwargs.setdefault('event_callbacks', PublisherEventCallbacks(use_default_callbacks=False))
        return super().create_publisher(*args, **kwargs)

    def create_subscription(self, *args, **kwargs):
        """Create a subscription without rclpy's default QoS-event handlers (as publishers)."""
        kwargs.setdefault(
            'event_callbacks', SubscriptionEventCallbacks(use_default_callbacks=False)
        )
        return super().create_subscription(*args, **kwargs)
