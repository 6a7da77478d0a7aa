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
Worst-case decision time of a release request.

Issue: every request up to the byte limit is decided in bounded time. Times the release node's two
steps without ROS: reading the text (strict language) and judging the release (fields, flight
order, flight construction), for a typical request and for hostile ones of up to
``max_request_bytes``; prints a table with each case's ratio to the typical request.

    .venv/bin/python bench/request_benchmark.py [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from football_ros.requests import (
    FlightOrder,
    MAX_REQUEST_BYTES,
    read_request,
    release_from_request,
    RequestError,
)

LIMIT = MAX_REQUEST_BYTES


def _fill(prefix: str, unit: str, suffix: str) -> str:
    """``prefix + unit * n + suffix`` as long as fits in LIMIT bytes."""
    n = (LIMIT - len(prefix) - len(suffix)) // len(unit)
    return prefix + unit * n + suffix


CASES = {
    'typical request': json.dumps(
        {'id': 'pass-1', 'speed': 25.0, 'spin_rpm': 650, 'beta0_deg': -2}
    ),
    'full-model request': json.dumps(
        {
            'id': 'wind',
            'model': 'full',
            'aero': {'wind': [0, -4, 0]},
            'ball_params': {'mass': 0.42},
            'position': [1, 2, 1.8],
        }
    ),
    'deep nesting [[[...': '[' * (LIMIT // 2) + ']' * (LIMIT // 2),
    'deep nesting {a: {a: ...': _fill('', '{a: ', ''),
    'deep block nesting': ''.join(' ' * (2 * i) + 'a:\n' for i in range(2000))[:LIMIT],
    'flat mapping, many keys': '{'
    + ', '.join(f'k{i}: 1' for i in range(20000))[: LIMIT - 2]
    + '}',
    'long list': _fill('{id: l, position: [', '1, ', '1]}'),
    'long string value': _fill('{id: s, ball: "', 'x', '"}'),
    'many digits': _fill('{id: d, speed: ', '9', '}'),
    'many exponents': _fill('[', '1e999, ', '1]'),
    'aliases everywhere': _fill('a: &x 1\n', 'b: *x\n', ''),
    'duplicate keys': _fill('{', 'speed: 1, ', 'speed: 2}'),
    'tags everywhere': _fill('[', '!!float 1, ', '1]'),
    'malformed at the end': '[' + ', '.join('1' for _ in range(40000))[: LIMIT - 4] + ', [}',
}


def decide(text: str) -> str:
    """Decide as the release node does, up to the flight order (no prediction, no ROS)."""
    try:
        request_id, keys = read_request(text)
        release = release_from_request(request_id, keys)
        order = FlightOrder.from_release(request_id, release, 'bench-1')
        FlightOrder.from_json(order.to_json()).flight(0.001)
        return 'accepted'
    except RequestError as exc:
        return f'rejected: {str(exc)[:50]}'


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--repeat', type=int, default=20)
    args = parser.parse_args()
    decide(CASES['typical request'])  # compile/load the kernels once
    rows = []
    for name, text in CASES.items():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            outcome = decide(text)
            times.append(time.perf_counter() - t0)
        rows.append((name, len(text.encode()), statistics.median(times), max(times), outcome))
    base = rows[0][2]
    print(f'{"case":26} {"bytes":>6} {"median ms":>10} {"max ms":>8} {"x typical":>10}  outcome')
    for name, size, med, worst, outcome in rows:
        print(
            f'{name:26} {size:6d} {med * 1e3:10.3f} {worst * 1e3:8.3f} '
            f'{med / base:10.1f}  {outcome}'
        )
    print(f'worst case: {max(r[3] for r in rows) * 1e3:.1f} ms (limit {LIMIT} bytes)')


if __name__ == '__main__':
    import results  # bench/results.py: the figures go to bench/RESULTS.md

    raise SystemExit(results.recorded('requests', main))
