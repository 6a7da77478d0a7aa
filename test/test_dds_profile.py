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
The package's Fast DDS profile: chosen only when the user has none, and really applied.

The process tests listen, as a participant of the test domain would, on the discovery port of
participant slot ``SLOT`` (Fast DDS sends its announcements to the ports of every slot on
127.0.0.1 under ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) and count the announcements (DATA(p))
of the process under test, told apart by its PID in the GUID prefix. The package's profile
announces every 0.2 s, Fast DDS's default every 3 s: in a 2 s window that is about 10 against
at most 1.
"""

import os
from pathlib import Path
import select
import socket
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

from football_ros.nodes import dds
import pytest

SLOT = 12  # a participant slot no test fills (ports of slots 0-31 receive announcements)
SPDP_WRITER = bytes([0x00, 0x01, 0x00, 0xC2])  # entity id of the participant announcer
USER_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="users_own" is_default_profile="true">
      <rtps><builtin><discovery_config>
        <leaseAnnouncement><sec>3</sec><nanosec>0</nanosec></leaseAnnouncement>
      </discovery_config></builtin></rtps>
    </participant>
  </profiles>
</dds>
"""


def test_the_profile_is_chosen_when_the_user_has_none(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    env = {'ROS_DOMAIN_ID': '7'}
    assert dds.use_package_profile(env) == str(dds.PROFILE_PATH)
    assert env == {'ROS_DOMAIN_ID': '7', 'FASTRTPS_DEFAULT_PROFILES_FILE': str(dds.PROFILE_PATH)}
    assert Path(env['FASTRTPS_DEFAULT_PROFILES_FILE']).is_file()


@pytest.mark.parametrize(
    'users',
    [
        {'FASTRTPS_DEFAULT_PROFILES_FILE': '/etc/my_profile.xml'},
        {'FASTRTPS_DEFAULT_PROFILES_FILE': ''},  # explicitly: Fast DDS's own defaults
        {'FASTDDS_DEFAULT_PROFILES_FILE': '/etc/my_profile.xml'},
    ],
)
def test_a_users_profile_variable_is_left_alone(users, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    env = dict(users)
    assert dds.use_package_profile(env) is None
    assert env == users


def test_a_profile_in_the_working_directory_is_left_alone(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'DEFAULT_FASTRTPS_PROFILES.xml').write_text(USER_PROFILE)
    env = {}
    assert dds.use_package_profile(env) is None
    assert env == {}


def test_the_profile_changes_only_the_announcement_period():
    ns = {'d': 'http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles'}
    root = ET.parse(dds.PROFILE_PATH).getroot()
    participants = root.findall('d:profiles/d:participant', ns)
    assert len(participants) == 1 and participants[0].get('is_default_profile') == 'true'
    config = participants[0].find('d:rtps/d:builtin/d:discovery_config', ns)
    assert [child.tag.split('}')[1] for child in config] == ['leaseAnnouncement']
    period = config.find('d:leaseAnnouncement', ns)
    seconds = int(period.find('d:sec', ns).text) + int(period.find('d:nanosec', ns).text) * 1e-9
    assert seconds == pytest.approx(0.2)  # and well inside the 20 s default lease duration


def _announcements(pid: int, settle: float = 1.0, window: float = 2.0) -> int:
    """
    Count the DATA(p) of process ``pid`` reaching slot SLOT's port in ``window`` seconds.

    Counting starts ``settle`` seconds after the call, past a new participant's five initial
    announcements (0.1 s apart).
    """
    domain = int(os.environ['ROS_DOMAIN_ID'])
    port = 7400 + 250 * domain + 10 + 2 * SLOT  # RTPS 9.6.1.1: metatraffic unicast, slot SLOT
    mark = (pid & 0xFFFF).to_bytes(2, 'little')  # Fast DDS: GUID prefix bytes 4-5 = the PID
    count = 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(('127.0.0.1', port))
        start = time.monotonic() + settle
        end = start + window
        while (now := time.monotonic()) < end:
            if not select.select([sock], [], [], end - now)[0]:
                continue
            data = sock.recv(65536)
            if (now >= start and data[:4] == b'RTPS' and data[12:14] == mark
                    and SPDP_WRITER in data):
                count += 1
    return count


@pytest.fixture
def no_profile_variables(monkeypatch):
    for name in dds.PROFILE_VARIABLES:
        monkeypatch.delenv(name, raising=False)


def test_a_node_announces_with_the_packages_profile(start_node, no_profile_variables):
    node = start_node('release')
    assert _announcements(node.pid) >= 4


def test_a_node_keeps_the_users_profile(start_node, no_profile_variables, tmp_path, monkeypatch):
    users = tmp_path / 'users_profile.xml'
    users.write_text(USER_PROFILE)
    monkeypatch.setenv('FASTRTPS_DEFAULT_PROFILES_FILE', str(users))
    node = start_node('release')
    assert _announcements(node.pid) <= 1


def test_echo_announces_with_the_packages_profile(no_profile_variables):
    echo = subprocess.Popen(
        [sys.executable, '-m', 'football_ros.cli', 'echo', 'football/pose', '--timeout', '4'],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        assert _announcements(echo.pid, settle=1.5, window=1.5) >= 3
    finally:
        echo.wait(timeout=30)
