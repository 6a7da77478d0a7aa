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
Plan requests: the keys of ``football/plan/request`` after the strict reader (no ROS).

The text goes through :func:`football_ros.requests.read_request` (strict YAML/JSON, bounded,
``id``); the other keys are read here. Plan keys: ``target`` [x, y, z] m, or ``receiver``
{position, velocity, time} (or the string ``odom``: the receiver Odometry the node follows),
``arrival_time`` s, ``arrival_window`` [t0, t1] s, ``objective``, ``max_speed`` m/s,
``elevation_range`` [min, max] deg, ``attitude``, ``tolerance`` m, ``catch_radius`` m,
``sigmas`` {key: sigma}, ``hit_n``, ``execute`` (bool), ``compare_arcs`` (bool: also the flat
and the lofted arc's hit probabilities, and which is more robust). Base release keys (ball, speed,
spin_rpm, position, model, moment, ball_params, aero) as in a release request. Unknown keys,
wrong types and out-of-range values raise :class:`PlanError` naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from typing import Any, Mapping

from .planner import ATTITUDES, OBJECTIVES, PlanError, Receiver
from ..physics.release import Release, ReleaseError

PLAN_KEYS = (
    'target',
    'receiver',
    'arrival_time',
    'arrival_window',
    'objective',
    'max_speed',
    'elevation_range',
    'attitude',
    'tolerance',
    'catch_radius',
    'sigmas',
    'hit_n',
    'execute',
    'compare_arcs',
)
BASE_KEYS = ('ball', 'speed', 'spin_rpm', 'position', 'model', 'moment', 'ball_params', 'aero')
MAX_HIT_N = 100_000


@dataclass
class PlanRequest:
    """A read plan request: :func:`football_ros.planning.plan` keyword arguments and extras."""

    options: dict[str, Any] = field(default_factory=dict)
    receiver_from_odometry: bool = False
    execute: bool = False
    catch_radius: float = 0.5
    sigmas: dict[str, float] = field(default_factory=dict)
    hit_n: int | None = None
    compare_arcs: bool = False


def _numbers(name: str, value: Any, size: int) -> list[float]:
    if not isinstance(value, list) or len(value) != size:
        raise PlanError(f"'{name}' must be a list of {size} numbers", name)
    out = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise PlanError(f"'{name}[{i}]' must be a number", name)
        try:
            v = float(v)
        except OverflowError:
            raise PlanError(f"'{name}[{i}]' is out of range", name) from None
        if not math.isfinite(v):
            raise PlanError(f"'{name}[{i}]' must be finite", name)
        out.append(v)
    return out


def _number(name: str, value: Any) -> float:
    return _numbers(name, [value], 1)[0]


def read_plan_request(data: Mapping[str, Any]) -> PlanRequest:
    """Return the :class:`PlanRequest` of a request's keys (``id`` removed); else PlanError."""
    if not isinstance(data, Mapping):
        raise PlanError('a plan request must be a mapping', 'request')
    unknown = sorted(set(data) - set(PLAN_KEYS) - set(BASE_KEYS))
    if unknown:
        shown = ', '.join(repr(k)[:40] for k in unknown[:5])
        raise PlanError(
            f'unknown key(s) {shown}; known: {", ".join(PLAN_KEYS + BASE_KEYS)}', 'request'
        )
    try:
        base = Release.from_mapping({k: data[k] for k in BASE_KEYS if k in data})
    except (ReleaseError, TypeError, ValueError) as exc:
        raise PlanError(str(exc)[:300], 'release') from None
    req = PlanRequest()
    opts: dict[str, Any] = {'base': base}
    if 'target' in data:
        opts['target'] = _numbers('target', data['target'], 3)
    rx = data.get('receiver')
    if rx == 'odom':
        req.receiver_from_odometry = True
    elif rx is not None:
        if not isinstance(rx, Mapping) or set(rx) - {'position', 'velocity', 'time'} or not (
            'position' in rx and 'velocity' in rx
        ):
            raise PlanError("'receiver' must be 'odom' or {position, velocity[, time]}",
                            'receiver')
        opts['receiver'] = Receiver(
            _numbers('receiver.position', rx['position'], 3),
            _numbers('receiver.velocity', rx['velocity'], 3),
            _number('receiver.time', rx.get('time', 0.0)),
        )
    if ('target' in data) == (rx is not None):
        raise PlanError("give exactly one of 'target' and 'receiver'", 'target')
    for key in ('arrival_time', 'max_speed', 'tolerance'):
        if key in data and data[key] is not None:
            opts[key] = _number(key, data[key])
    for key in ('arrival_window', 'elevation_range'):
        if key in data and data[key] is not None:
            opts[key] = tuple(_numbers(key, data[key], 2))
    for key, choices in (('objective', OBJECTIVES), ('attitude', ATTITUDES)):
        if key in data:
            if data[key] not in choices:
                raise PlanError(f"'{key}' must be one of {', '.join(choices)}", key)
            opts[key] = data[key]
    if 'catch_radius' in data:
        req.catch_radius = _number('catch_radius', data['catch_radius'])
    if 'sigmas' in data:
        sig = data['sigmas']
        if not isinstance(sig, Mapping):
            raise PlanError("'sigmas' must be a mapping of release keys to numbers", 'sigmas')
        req.sigmas = {str(k): _number(f'sigmas.{k}', v) for k, v in sig.items()}
    if 'hit_n' in data:
        n = data['hit_n']
        if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= MAX_HIT_N:
            raise PlanError(f"'hit_n' must be an integer in [0, {MAX_HIT_N}]", 'hit_n')
        req.hit_n = n
    for key in ('execute', 'compare_arcs'):
        if key in data:
            if not isinstance(data[key], bool):
                raise PlanError(f"'{key}' must be true or false", key)
            setattr(req, key, data[key])
    req.options = opts
    return req
