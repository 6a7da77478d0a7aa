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

"""The topic table: every topic name of nodes/qos.py has its type and its msg_docs row."""

from pathlib import Path

from football_ros.nodes import qos
from football_ros.nodes.topics import TOPICS, type_name

REPO = Path(__file__).resolve().parents[1]


def test_every_topic_name_is_in_the_table():
    names = {
        value
        for name, value in vars(qos).items()
        if name.isupper()
        and isinstance(value, str)
        and not name.endswith('SERVICE')
        and not value.startswith('~/')  # the simulator's simulation_interfaces services
    }
    assert names == set(TOPICS)


def test_every_topic_has_a_page_naming_its_type():
    index = (REPO / 'msg_docs' / 'README.md').read_text()
    for topic, (cls, _profile) in TOPICS.items():
        assert f'`{topic}`' in index, topic
        assert type_name(cls) in index, (topic, type_name(cls))


def test_run_time_topics_are_patterns_of_the_table_with_a_page():
    from football_ros.nodes.topics import known_names, lookup, PATTERNS
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
    from nav_msgs.msg import Odometry, Path as PathMsg

    index = (REPO / 'msg_docs' / 'README.md').read_text()
    for pattern in PATTERNS:
        assert f'`{pattern.template}`' in index, pattern.template
    assert lookup(qos.entity_topic('ball_2', 'pose')) == (PoseStamped, qos.STATE)
    assert lookup(qos.entity_topic('b', 'odom')) == (Odometry, qos.STATE)
    assert lookup(qos.track_topic(17, qos.LANDING)) == (PoseWithCovarianceStamped, qos.STATE)
    assert lookup(qos.track_topic(3, qos.PREDICTED_PATH)) == (PathMsg, qos.STATE)
    assert lookup(qos.POSE) == TOPICS[qos.POSE] and lookup(qos.TF) == TOPICS[qos.TF]
    for name in ('football/a/b/pose', 'football/1a/pose', 'football/b1/twist', 'b1/pose',
                 'football/track_x/estimate', 'football/track_3/release/request', ''):
        assert lookup(name) is None, name
    assert set(TOPICS) <= set(known_names())
