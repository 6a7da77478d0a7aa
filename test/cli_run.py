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

"""The football-ros command as the tests run it: this interpreter, ``-m football_ros.cli``."""

import subprocess
import sys

CLI = (sys.executable, '-m', 'football_ros.cli')


def run_cli(*args: str, timeout: float = 120.0, **kwargs) -> subprocess.CompletedProcess:
    """Run ``football-ros ARGS``; its output captured as text."""
    return subprocess.run(
        [*CLI, *args], capture_output=True, text=True, timeout=timeout, **kwargs
    )
