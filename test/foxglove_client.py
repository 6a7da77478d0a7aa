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
A headless Foxglove WebSocket client (the protocol, not football_ros): subscribe and decode.

Speaks ``foxglove.websocket.v1`` (the SDK's ``foxglove.sdk.v1`` too): reads serverInfo and the
channel advertisements, subscribes by topic, and decodes each message by the schema the server
advertised for it: ``cdr`` with the ``ros2msg`` definition (mcap_ros2's dynamic decoder, which
knows no ROS install) and ``json``. Used by test_view_node.py and bench/view_benchmark.py.
"""

from __future__ import annotations

import json
import struct
import time

from mcap_ros2._dynamic import generate_dynamic
from websockets.sync.client import connect

SUBPROTOCOLS = ['foxglove.websocket.v1', 'foxglove.sdk.v1']
OP_MESSAGE_DATA, OP_TIME = 1, 2


class FoxgloveClient:
    """One connection; ``poll`` takes what arrived, ``messages[topic]`` holds it decoded."""

    def __init__(self, url: str, decode: bool = True, timeout: float = 10.0) -> None:
        self.ws = connect(url, subprotocols=SUBPROTOCOLS, max_size=None,
                          open_timeout=timeout).__enter__()  # closed by close()
        self.decode = decode
        self.server_info: dict = {}
        self.channels: dict[str, dict] = {}  # topic -> advertisement
        self.messages: dict[str, list] = {}  # topic -> [(receive ns, log time ns, message)]
        self.times: list[int] = []  # server time broadcasts [ns]
        self.statuses: list[dict] = []
        self._subs: dict[int, str] = {}  # subscription id -> topic
        self._decoders: dict[str, object] = {}

    def poll(self, seconds: float) -> None:
        """Receive for ``seconds`` [s] (at least one read)."""
        end = time.monotonic() + seconds
        while True:
            try:
                frame = self.ws.recv(timeout=max(0.0, end - time.monotonic()))
            except TimeoutError:
                return
            self._take(frame, time.time_ns())
            if time.monotonic() >= end:
                return

    def wait_for(self, predicate, timeout: float = 20.0, what: str = 'condition') -> None:
        """Poll until ``predicate()`` holds (AssertionError after ``timeout`` [s])."""
        end = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > end:
                raise AssertionError(f'timed out waiting for {what}')
            self.poll(0.05)

    def _take(self, frame, received_ns: int) -> None:
        if isinstance(frame, str):
            msg = json.loads(frame)
            op = msg.get('op')
            if op == 'serverInfo':
                self.server_info = msg
            elif op == 'advertise':
                for channel in msg['channels']:
                    self.channels[channel['topic']] = channel
            elif op == 'unadvertise':
                gone = set(msg['channelIds'])
                self.channels = {t: c for t, c in self.channels.items() if c['id'] not in gone}
            elif op == 'status':
                self.statuses.append(msg)
            return
        op = frame[0]
        if op == OP_MESSAGE_DATA:
            sub_id, log_time = struct.unpack_from('<IQ', frame, 1)
            topic = self._subs.get(sub_id)
            if topic is not None:
                payload = bytes(frame[13:])
                value = self._decode(topic, payload) if self.decode else payload
                self.messages.setdefault(topic, []).append((received_ns, log_time, value))
        elif op == OP_TIME:
            self.times.append(struct.unpack_from('<Q', frame, 1)[0])

    def _decode(self, topic: str, payload: bytes):
        channel = self.channels[topic]
        if channel['encoding'] == 'json':
            return json.loads(payload)
        assert channel['encoding'] == 'cdr' and channel['schemaEncoding'] == 'ros2msg'
        decoder = self._decoders.get(topic)
        if decoder is None:
            name = channel['schemaName']
            decoder = self._decoders[topic] = generate_dynamic(name, channel['schema'])[name]
        return decoder(payload)

    def subscribe(self, *topics: str) -> None:
        """Subscribe to advertised ``topics`` (KeyError for one not advertised)."""
        subs = []
        for topic in topics:
            sub_id = len(self._subs) + 1
            self._subs[sub_id] = topic
            subs.append({'id': sub_id, 'channelId': self.channels[topic]['id']})
        self.ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subs}))

    def unsubscribe_all(self) -> None:
        """Unsubscribe from every subscription."""
        self.ws.send(json.dumps({'op': 'unsubscribe', 'subscriptionIds': list(self._subs)}))
        self._subs.clear()

    def close(self) -> None:
        """Close the connection."""
        self.ws.close()
