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
Release requests (text in) and flight orders (release node -> simulator), no ROS needed.

A request is one mapping, in the strict YAML/JSON language of :mod:`football_ros.strict_yaml`,
of the release keys (``Release.FIELDS``) plus ``id``. :func:`read_request` is the cheap first
step (size, language, mapping, id), :func:`release_from_request` the second (the release's
rules, :mod:`football_ros.physics.release`). Every failure raises :class:`RequestError` with a
one-sentence reason naming the field and the id the answer goes to.

Ids: a client's ``id`` (a string or an integer of 1-128 printable characters) names its answer.
A request without one is answered as ``req-<n>``; one whose id cannot be used (not printable,
too long, empty, or of one of these two reserved forms) as ``id-<h>``, h = the first 16 hex
digits of the SHA-256 of the id's text (UTF-8), so that its client can still match it.

A flight order is the JSON the release node sends the simulator: the full rigid-body initial
state in ``field`` plus ball, overrides, model and moment, so requests given as text or as an
Odometry take one path. A :class:`FlightOrder` is valid by construction (the rules of
:func:`football_ros.physics.release.check_settings` and
:meth:`football_ros.physics.InitialState.from_rigid_body`): the release node builds one, the
simulator reads one with :meth:`FlightOrder.from_json`, both by the same rules.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import hashlib
import itertools
import json
import re
from typing import Any

from .physics import BallPreset, Flight, InitialState, Release
from .physics.release import check_settings
from .strict_yaml import brief, load_strict, StrictParseError

MAX_REQUEST_BYTES = 65536
MAX_ID_LENGTH = 128
MAX_REASON = 400
"""Characters of a rejection reason (a safety net over every echo of user text)."""
ORDER_KEYS = (
    'id',
    'order',
    'ball',
    'ball_params',
    'model',
    'moment',
    'aero',
    'position',
    'velocity',
    'orientation',
    'angular_velocity',
)
RESERVED_ID = re.compile(r'(req-[0-9]+|id-[0-9a-f]{16})')
"""The forms of the ids the package makes up; a client's id of either form is refused."""
_counter = itertools.count(1)


class RequestError(ValueError):
    """A rejected request: ``request_id`` (recovered or made up) and a one-sentence reason."""

    def __init__(self, request_id: str, reason: str) -> None:
        super().__init__(capped(reason))
        self.request_id = request_id


def capped(text: str, limit: int = MAX_REASON) -> str:
    """Return ``text`` cut to ``limit`` characters (marked with '...')."""
    return text if len(text) <= limit else text[: limit - 3] + '...'


def made_up_id(prefix: str = 'req') -> str:
    """Return a fresh id for a request that brought none: ``req-<n>``."""
    return f'{prefix}-{next(_counter)}'


def printable_id(raw: Any, key: str = 'id') -> str:
    """Validate a name: a string or an integer of 1-128 printable characters."""
    if isinstance(raw, bool) or not isinstance(raw, (str, int)):
        raise ValueError(f"'{key}' must be a string or an integer, got {brief(raw)}")
    text = str(raw)
    if not text or len(text) > MAX_ID_LENGTH or not text.isprintable():
        raise ValueError(f"'{key}' must be 1 to {MAX_ID_LENGTH} printable characters")
    return text


def check_id(raw: Any) -> str:
    """Validate a client's correlation id: :func:`printable_id`, and not of a reserved form."""
    text = printable_id(raw)
    if RESERVED_ID.fullmatch(text):
        raise ValueError(
            "'id' must not have the form req-<n> or id-<16 hex digits>: the package names "
            'the answers to requests without a usable id so'
        )
    return text


def answer_id(raw: Any) -> str:
    """
    Return the name the answer to a request with id ``raw`` goes under (module docstring).

    ``raw`` itself when usable; ``id-<h>`` for a string or integer that :func:`check_id`
    refuses; a fresh ``req-<n>`` for anything else.
    """
    try:
        return check_id(raw)
    except ValueError:
        pass
    if isinstance(raw, bool) or not isinstance(raw, (str, int)):
        return made_up_id()
    digest = hashlib.sha256(str(raw).encode('utf-8', errors='surrogatepass')).hexdigest()
    return f'id-{digest[:16]}'


def read_request(text: str, max_bytes: int = MAX_REQUEST_BYTES) -> tuple[str, dict]:
    """
    Read a request's text (size, strict language, mapping, id): the cheap first step.

    Returns (id, the other keys as plain data) or raises RequestError. Costs tens of
    microseconds for a usual request and is bounded by ``max_bytes`` for any text.
    """
    if not isinstance(text, str):
        raise RequestError(made_up_id(), 'the request must be text')
    size = len(text.encode('utf-8', errors='replace'))
    if size > max_bytes:
        raise RequestError(
            made_up_id(), f'the request is {size} bytes, more than the {max_bytes} accepted'
        )
    try:
        data = load_strict(text)
    except StrictParseError as exc:
        raise RequestError(_recovered_id(exc.partial), str(exc)) from None
    if not isinstance(data, dict):
        got = 'an empty text' if data is None else f'a {type(data).__name__}'
        raise RequestError(
            made_up_id(),
            f'the request must be one mapping of release keys, got {got} '
            "('{}' asks for the default release)",
        )
    if 'id' not in data:
        return made_up_id(), data
    raw = data.pop('id')
    try:
        return check_id(raw), data
    except ValueError as exc:
        raise RequestError(answer_id(raw), str(exc)) from None


def release_from_request(request_id: str, data: dict) -> Release:
    """
    Second step: return the Release a request's keys mean.

    Else raise RequestError naming the field.
    """
    try:
        return Release.from_mapping(data)
    except (TypeError, ValueError) as exc:  # ReleaseError, or a wrongly typed entry
        raise RequestError(request_id, str(exc)) from None


def parse_release_request(text: str, max_bytes: int = MAX_REQUEST_BYTES) -> tuple[str, Release]:
    """Parse a release request; return (id, Release) or raise RequestError."""
    request_id, data = read_request(text, max_bytes)
    return request_id, release_from_request(request_id, data)


def _recovered_id(partial: dict) -> str:
    """Return the answer's name for a request not readable to its end (its id if first)."""
    return answer_id(partial['id']) if 'id' in partial else made_up_id()


def _vector(data: dict, key: str, size: int) -> list[float]:
    value = data.get(key)
    if (
        not isinstance(value, list)
        or len(value) != size
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        raise ValueError(f"'{key}' must be a list of {size} numbers, got {brief(value)}")
    try:
        return [float(v) for v in value]
    except OverflowError:
        raise ValueError(f"'{key}' holds a number too large for a float") from None


class OrderError(ValueError):
    """A refused flight order; ``name`` is what its acknowledgement is named (order, else id)."""

    def __init__(self, name: str, reason: str) -> None:
        super().__init__(capped(reason))
        self.name = name


@dataclass(frozen=True)
class FlightOrder:
    """
    What the simulator needs to fly a ball: ids, ball, model, moment and initial state.

    ``request_id`` is the client's id; ``order_id`` names this hand-off uniquely (the
    simulator's acknowledgement carries it), empty for orders that bring none. Validated on
    construction (raises ValueError); ``initial`` must come from a validated release or from
    :meth:`InitialState.from_rigid_body`.
    """

    request_id: str
    ball_name: str
    ball_params: dict
    model: str
    moment: str
    initial: InitialState
    aero: dict = field(default_factory=dict)
    order_id: str = ''

    def __post_init__(self) -> None:
        printable_id(self.request_id)
        if self.order_id:
            printable_id(self.order_id, 'order')
        if not isinstance(self.initial, InitialState):
            raise ValueError('a flight order needs an InitialState')
        check_settings(self.ball_name, self.ball_params, self.model, self.moment, self.aero)

    @property
    def name(self) -> str:
        """Name of the simulator's acknowledgement: the order id, else the request id."""
        return self.order_id or self.request_id

    def ball(self) -> BallPreset:
        settings = self.ball_name, self.ball_params, self.model, self.moment, self.aero
        return check_settings(*settings)[0]

    def flight(self, step: float, model: str | None = None) -> Flight:
        """
        Return the Flight this order means (``model`` overrides the ordered one).

        Raises ValueError (ReleaseError) when it cannot be flown with this ``step`` [s].
        """
        model = model or self.model
        ball, aero = check_settings(
            self.ball_name,
            self.ball_params,
            model,
            self.moment,
            self.aero if model == 'full' else {},
        )
        return Flight(ball, self.initial, model, self.moment, step, aero)

    @staticmethod
    def from_release(request_id: str, release: Release, order_id: str = '') -> 'FlightOrder':
        return FlightOrder(
            request_id,
            release.ball,
            dict(release.ball_params),
            release.model,
            release.moment,
            release.initial_state(),
            dict(release.aero),
            order_id,
        )

    def to_json(self) -> str:
        st = self.initial
        data = {
            'id': self.request_id,
            'ball': self.ball_name,
            'ball_params': self.ball_params,
            'model': self.model,
            'moment': self.moment,
            'aero': self.aero,
            'position': st.position.tolist(),
            'velocity': st.velocity.tolist(),
            'orientation': st.attitude.tolist(),
            'angular_velocity': st.angular_velocity().tolist(),
        }
        if self.order_id:
            data['order'] = self.order_id
        return json.dumps(data)

    @staticmethod
    def from_json(text: str, max_bytes: int = MAX_REQUEST_BYTES) -> 'FlightOrder':
        """
        Inverse of :meth:`to_json`: read and validate a hand-off, in one parse.

        Raises :class:`OrderError` (a ValueError) whose ``name`` is the order's (else its
        id, else 'unknown'), so that even a refused order is acknowledged by its name.
        """
        if not isinstance(text, str) or len(text.encode('utf-8', errors='replace')) > max_bytes:
            raise OrderError(
                'unknown', f'a flight order must be JSON text of at most {max_bytes} bytes'
            )
        try:
            data = load_strict(text)
        except StrictParseError as exc:
            raise OrderError(_order_name(exc.partial), str(exc)) from None
        if not isinstance(data, dict):
            raise OrderError('unknown', 'a flight order must be a JSON object')
        try:
            return FlightOrder.from_mapping(data)
        except (ValueError, TypeError, ArithmeticError) as exc:
            raise OrderError(_order_name(data), str(exc) or type(exc).__name__) from None

    @staticmethod
    def from_mapping(data: dict) -> 'FlightOrder':
        """Build from the plain data of :meth:`to_json` (raises ValueError naming the key)."""
        unknown = sorted(set(data) - set(ORDER_KEYS))
        if unknown:
            raise ValueError(f'unknown flight-order key(s) {brief(", ".join(unknown))}')
        missing = [
            k
            for k in ('id', 'position', 'velocity', 'orientation', 'angular_velocity')
            if k not in data
        ]
        if missing:
            raise ValueError(f'the flight order lacks {", ".join(missing)}')
        initial = InitialState.from_rigid_body(
            _vector(data, 'position', 3),
            _vector(data, 'velocity', 3),
            _vector(data, 'orientation', 4),
            _vector(data, 'angular_velocity', 3),
        )
        return FlightOrder(
            printable_id(data['id']),
            data.get('ball', 'american'),
            data.get('ball_params') or {},
            data.get('model', 'paper'),
            data.get('moment', 'linear'),
            initial,
            data.get('aero') or {},
            printable_id(data['order'], 'order') if 'order' in data else '',
        )


def _order_name(data: dict) -> str:
    """Return the name to acknowledge an order by: its ``order``, else its ``id``."""
    for key in ('order', 'id'):
        try:
            return printable_id(data[key])
        except (KeyError, ValueError):
            continue
    return 'unknown'
