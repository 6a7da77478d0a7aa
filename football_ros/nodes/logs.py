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
Log lines that a sender can trigger at will, at most one per call site per period.

rclpy's logger reads the calling frame's source file on every call (``inspect.getframeinfo``)
before its ``throttle_duration_sec`` decides, about 2 ms of CPU a call in a process that has
imported numpy, scipy and numba: a suppressed line cost as much as a printed one, so that a
flood of refused fixes or a hundred balls landing in one tick cost the node seconds.
:func:`throttled` decides first, on a clock, per call site and logger; a suppressed line costs
a dictionary lookup. A printed line goes through rclpy as before (console, /rosout), attributed
to the caller (this file is one of rclpy's internal callers).
"""

from __future__ import annotations

import os
import sys
import time

from rclpy.impl import rcutils_logger

rcutils_logger._internal_callers.append(os.path.realpath(__file__))  # the caller: the node's line

_last_ns: dict[tuple, int] = {}  # (logger, code, line) -> when its last line was printed


def throttled(logger, severity: str, text: str, period_s: float) -> bool:
    """
    Log ``text`` unless this call site logged through ``logger`` less than ``period_s`` ago.

    ``logger`` an rclpy logger (``node.get_logger()``), ``severity`` 'info', 'warning' or
    'error'. Returns whether the line was printed.
    """
    caller = sys._getframe(1)
    key = (logger.name, caller.f_code, caller.f_lineno)
    now = time.monotonic_ns()
    last = _last_ns.get(key)
    if last is not None and now - last < period_s * 1e9:
        return False
    _last_ns[key] = now
    getattr(logger, severity)(text)
    return True
