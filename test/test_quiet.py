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

"""QuietNode: its publishers and subscriptions carry no QoS-event handlers unless given some."""

from football_ros.nodes.quiet import QuietNode
import rclpy
from rclpy.context import Context
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.node import Node
from std_msgs.msg import String


def test_quiet_node_creates_no_event_handlers_unless_asked():
    context = Context()
    rclpy.init(context=context)
    try:
        plain = Node('plain_node', context=context)
        quiet = QuietNode('quiet_node', context=context)
        # rclpy's default: handlers on both sides (each a waitable the executor walks)
        assert plain.create_publisher(String, 'a', 1).event_handlers
        assert plain.create_subscription(String, 'a', lambda _m: None, 1).event_handlers
        assert quiet.create_publisher(String, 'a', 1).event_handlers == []
        assert quiet.create_subscription(String, 'a', lambda _m: None, 1).event_handlers == []
        asked = PublisherEventCallbacks(matched=lambda _info: None, use_default_callbacks=False)
        pub = quiet.create_publisher(String, 'b', 1, event_callbacks=asked)
        assert len(pub.event_handlers) == 1  # the callbacks given are used as given
        assert len(list(quiet.waitables)) == 1 and len(list(plain.waitables)) > 1
        plain.destroy_node()
        quiet.destroy_node()
    finally:
        rclpy.shutdown(context=context)
