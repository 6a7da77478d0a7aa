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

"""rviz/football.rviz: loads as YAML (as rviz2 reads it) and shows only topics the package has."""

import inspect
from pathlib import Path

from football_ros.nodes import messages, qos
from football_ros.nodes.topics import TOPICS, type_name
from football_ros.physics.frames import FIELD_FRAME
from rclpy.qos import ReliabilityPolicy
import yaml

RVIZ = Path(__file__).resolve().parents[1] / 'rviz' / 'football.rviz'
# rviz2 display class -> the message type its topic must carry
DISPLAY_TYPES = {
    'rviz_default_plugins/MarkerArray': 'visualization_msgs/msg/MarkerArray',
    'rviz_default_plugins/Pose': 'geometry_msgs/msg/PoseStamped',
}


def displays(items):
    for display in items:
        yield display
        yield from displays(display.get('Displays', []))  # display groups


def package_topics():
    return set(TOPICS)


def resolve(name, namespace='/'):
    return name if name.startswith('/') else namespace.rstrip('/') + '/' + name


def test_rviz_config_loads_and_every_topic_exists():
    config = yaml.safe_load(RVIZ.read_text())
    manager = config['Visualization Manager']
    assert manager['Global Options']['Fixed Frame'] == FIELD_FRAME
    shown = list(displays(manager['Displays']))
    classes = [d['Class'] for d in shown]
    assert {'rviz_default_plugins/TF', 'rviz_default_plugins/MarkerArray'} <= set(classes)
    topics = {resolve(t) for t in package_topics()}
    with_topic = [d for d in shown if 'Topic' in d]
    assert with_topic
    for display in with_topic:
        topic = display['Topic']['Value']
        assert resolve(topic) in topics, topic
        assert not topic.startswith('/')  # relative, so a pushed namespace applies
        cls, profile = TOPICS[topic]
        assert DISPLAY_TYPES[display['Class']] == type_name(cls)
        # The subscription's QoS must match what the simulator offers.
        offered = (
            'Reliable' if profile.reliability == ReliabilityPolicy.RELIABLE else 'Best Effort'
        )
        assert display['Topic']['Reliability Policy'] in (offered, 'Best Effort')
        assert display['Topic']['Durability Policy'] == 'Volatile'


def test_marker_namespace_and_tf_frames_match_the_simulator():
    config = yaml.safe_load(RVIZ.read_text())
    shown = list(displays(config['Visualization Manager']['Displays']))
    [markers] = [d for d in shown if d['Class'] == 'rviz_default_plugins/MarkerArray']
    default_ns = inspect.signature(messages.markers).parameters['namespace'].default
    assert markers['Namespaces'] == {default_ns: True}
    [tf] = [d for d in shown if d['Class'] == 'rviz_default_plugins/TF']
    assert tf['Enabled'] and tf['Frames']['All Enabled']
    assert qos.TF in package_topics()  # /tf is one of the package's topics
