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

"""use_sim_time: the release node with /clock from the simulator (publish_clock:=true)."""

import time

from diagnostic_msgs.msg import DiagnosticStatus
from football_ros.nodes import qos
from geometry_msgs.msg import PoseStamped
from std_msgs.msg import String


def test_release_node_under_sim_time_accepts_and_the_flight_runs_on_sim_time(
    start_node, collector
):
    start_node(
        'simulator',
        '--ros-args',
        '-p',
        'publish_clock:=true',
        '-p',
        'publish_rate:=200.0',
        '-p',
        'real_time_factor:=0.5',
    )
    start_node('release', '--ros-args', '-p', 'use_sim_time:=true')
    collector.subscribe(DiagnosticStatus, qos.RELEASE_RESPONSE, qos.REQUEST)
    collector.subscribe(PoseStamped, qos.POSE, qos.STATE)
    requests = collector.publisher(String, qos.RELEASE_REQUEST, qos.REQUEST)
    collector.wait_for_subscribers(requests)
    answer = None
    for k in range(10):  # a request lost to discovery right after start-up is sent again
        requests.publish(String(data=f'{{id: sim-{k}, speed: 20}}'))
        try:
            collector.wait_for(lambda: collector.get(qos.RELEASE_RESPONSE), 3.0, 'an answer')
        except AssertionError:
            continue
        answer = collector.get(qos.RELEASE_RESPONSE)[0]
        if answer.level in (b'\x00', 0):
            break
        time.sleep(0.5)
        collector.clear()
    assert answer is not None and answer.level in (b'\x00', 0), answer
    collector.wait_for(lambda: len(collector.get(qos.POSE)) >= 100, 15.0, '100 poses')
    stamps = [
        p.header.stamp.sec * 1_000_000_000 + p.header.stamp.nanosec
        for p in collector.get(qos.POSE)[:100]
    ]
    # Simulated time: 0.5 x 1/200 s per tick, far from the wall clock's epoch seconds.
    assert {b - a for a, b in zip(stamps, stamps[1:])} == {2_500_000} and stamps[0] < 600e9
