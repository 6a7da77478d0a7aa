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

"""The viewer's server socket: Nagle's algorithm off for every viewer (no ROS involved)."""

import os
from pathlib import Path
import socket
import sys
import time

from football_ros.nodes.view import no_delay
import foxglove
import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')


def _accepted_no_delay(port: int) -> list[int]:
    """TCP_NODELAY of this process's established sockets whose local port is ``port``."""
    inodes = set()
    for table in ('/proc/net/tcp', '/proc/net/tcp6'):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == '01' and int(fields[1].rsplit(':', 1)[1], 16) == port:
                inodes.add(f'socket:[{fields[9]}]')
    values = []
    for fd in os.listdir('/proc/self/fd'):
        try:
            if os.readlink(f'/proc/self/fd/{fd}') in inodes:
                with socket.socket(fileno=os.dup(int(fd))) as sock:
                    values.append(sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY))
        except OSError:
            continue
    return values


@pytest.mark.parametrize('set_it', [False, True])
def test_a_viewer_connection_has_nagle_off_only_with_no_delay(set_it):
    server = foxglove.start_server(host='127.0.0.1', port=0)
    try:
        if set_it:
            assert no_delay(server.port) == 1  # the one listening socket
        with socket.create_connection(('127.0.0.1', server.port), timeout=10):
            end = time.monotonic() + 20.0
            while not (seen := _accepted_no_delay(server.port)) and time.monotonic() < end:
                time.sleep(0.01)  # until the server has accepted the connection
            assert seen == [1 if set_it else 0]
    finally:
        server.stop()


def test_no_delay_finds_nothing_on_a_port_nobody_here_listens_on():
    with socket.socket() as other:
        other.bind(('127.0.0.1', 0))  # bound, not listening
        assert no_delay(other.getsockname()[1]) == 0
