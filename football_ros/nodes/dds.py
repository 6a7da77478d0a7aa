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
The package's Fast DDS profile: faster participant announcements, unless the user has their own.

Every process of the package calls :func:`use_package_profile` before ``rclpy.init()`` (the
participant reads the variable when it is created). The reason and the one setting are in
``fastdds_profile.xml`` beside this file; bench/first_throw_benchmark.py measures the effect.
No ROS imports: setting a variable is all this does (other RMW implementations ignore it).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import MutableMapping

PROFILE_PATH = Path(__file__).with_name('fastdds_profile.xml')
PROFILE_VARIABLES = ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE')
"""Fast DDS 2.x (Jazzy) reads the first, Fast DDS 3.x the second; either set means: theirs."""
CWD_PROFILE = 'DEFAULT_FASTRTPS_PROFILES.xml'
"""Fast DDS also loads this file from the working directory: a user's profile too."""


def use_package_profile(environ: MutableMapping[str, str] | None = None) -> str | None:
    """
    Point Fast DDS at the package's profile if the user has not chosen one.

    Leaves ``environ`` (default ``os.environ``) alone when either profile variable is present
    (even empty: an explicit "Fast DDS defaults"), when ``DEFAULT_FASTRTPS_PROFILES.xml`` is in
    the working directory, or when the profile file is not installed. Returns the path it set,
    or None.
    """
    env = os.environ if environ is None else environ
    if any(name in env for name in PROFILE_VARIABLES) or Path(CWD_PROFILE).exists():
        return None
    if not PROFILE_PATH.is_file():
        return None
    env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(PROFILE_PATH)
    return str(PROFILE_PATH)
