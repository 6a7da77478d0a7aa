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

"""Helpers for the cross-process tests (ROS imports; the pure-physics tests do not need them)."""

from diagnostic_msgs.msg import DiagnosticArray
from football_ros.nodes import qos
from football_ros.physics import Release
from football_ros.requests import FlightOrder
from std_msgs.msg import String


def resend_until(collector, send, done, what: str, tries: int = 10, wait: float = 2.0) -> int:
    """
    Call ``send(k)`` until ``done()`` holds within ``wait`` [s] of a send; return that k.

    Right after start-up DDS discovery may still drop a message (a reliable writer matched on
    our side only), so a message that had no effect is sent again, ``tries`` times at most.
    """
    for k in range(tries):
        send(k)
        try:
            collector.wait_for(done, wait, what)
            return k
        except AssertionError:
            continue
    raise AssertionError(f'no {what} after {tries} sends')


def order_flight(collector, release: Release, request_id: str):
    """
    Send a flight order straight to the simulator and wait for its 'released' event.

    As the release node does; an order lost to DDS discovery right after start-up is sent
    again.
    """
    if qos.DIAGNOSTICS not in collector.messages:
        collector.subscribe(DiagnosticArray, qos.DIAGNOSTICS, qos.DIAGNOSTICS_QOS)
    pub = collector.publisher(String, qos.FLIGHT_ORDER, qos.ORDER)
    collector.wait_for_subscribers(pub)
    text = FlightOrder.from_release(request_id, release).to_json()

    def released():
        return any(
            kv.key == 'flight_id' and kv.value == request_id
            for arr in collector.get(qos.DIAGNOSTICS)
            for st in arr.status
            if st.name.endswith('event')
            for kv in st.values
        )

    resend_until(collector, lambda _k: pub.publish(String(data=text)), released, 'released event')


def landed_event(collector):
    return any(
        s.values and any(kv.key == 'event' and kv.value == 'landed' for kv in s.values)
        for arr in collector.get(qos.DIAGNOSTICS)
        for s in arr.status
    )


def call(collector, srv_type, name, request, timeout=10.0):
    client = collector.node.create_client(srv_type, name)
    assert client.wait_for_service(timeout_sec=timeout), f'service {name} not available'
    future = client.call_async(request)
    collector.wait_for(future.done, timeout, f'{name} response')
    return future.result()
