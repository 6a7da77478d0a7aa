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

The request language is strict: the JSON-compatible subset of YAML. A request is one mapping of
the release keys (``Release.FIELDS``) plus ``id``; values are plain scalars, flow or block
mappings and sequences, nested at most ``MAX_DEPTH`` levels. Scalars read as JSON reads them:
``true``/``false``, ``null``/``~``, decimal numbers (``12``, ``-3.5``, ``1e3``); anything else
(``0x14``, ``2_0``, ``.inf``, ``yes``) is a string, so a number field refuses it. Tags
(``!!float``, ``!!binary``, ...), anchors, aliases, merge keys (``<<``), duplicate keys and
non-string keys are rejected, and so are mappings or lists of more than ``MAX_ITEMS``
entries. Every request up to the byte limit is decided in bounded time
(libyaml's event parser, stopped at the first violation). Every failure raises
:class:`RequestError` with a one-sentence reason naming the field and the best id recovered.

A flight order is the JSON the release node sends the simulator: the full rigid-body initial
state in ``field`` plus ball, overrides, model and moment, so requests given as text or as an
Odometry take one path; :meth:`FlightOrder.from_json` is the one validation both nodes apply.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import itertools
import json
import math
import re
from typing import Any

import numpy as np
import yaml

from .physics import BallPreset, Flight, get_preset, InitialState, Release
from .physics.aero import AeroModel
from .physics.release import MODELS, MOMENT_CURVES

MAX_REQUEST_BYTES = 65536
MAX_ID_LENGTH = 128
MAX_DEPTH = 4
"""Nesting levels a request may use: request -> aero -> wind list needs 3."""
MAX_ITEMS = 64
"""Entries a mapping or items a list may hold (a release has 15 keys; lists hold 3 or 4)."""
MAX_ECHO = 60
"""Characters of a user's value echoed in an error message."""
MAX_DIGITS = 40
"""Digits a number may have (longer ones are refused before any conversion)."""
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
_counter = itertools.count(1)
_Parser = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)  # libyaml when available


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


def brief(value: Any, limit: int = MAX_ECHO) -> str:
    """Return repr of a value cut to ``limit`` characters, for error messages."""
    text = repr(value) if not isinstance(value, str) else repr(value[: limit + 1])
    return text if len(text) <= limit else text[: limit - 3] + '...'


def check_id(raw: Any) -> str:
    """Validate a correlation id (string or integer, 1-128 printable characters)."""
    if isinstance(raw, bool) or not isinstance(raw, (str, int)):
        raise ValueError(f"'id' must be a string or an integer, got {brief(raw)}")
    text = str(raw)
    if not text or len(text) > MAX_ID_LENGTH or not text.isprintable():
        raise ValueError(f"'id' must be 1 to {MAX_ID_LENGTH} printable characters")
    return text


_INT = re.compile(r'[-+]?[0-9]+')
_FLOAT = re.compile(r'[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?')
_NULL = ('null', '~', '')
_BOOL = {'true': True, 'false': False}


def _scalar(event: yaml.ScalarEvent) -> Any:
    """Resolve a scalar as JSON would (plain scalars only; quoted ones are strings)."""
    text = event.value
    if not _plain(event):  # quoted or block scalar: always a string
        return text
    if text in _NULL:
        return None
    if text in _BOOL:
        return _BOOL[text]
    if _FLOAT.fullmatch(text):
        if sum(c.isdigit() for c in text) > MAX_DIGITS and not ('e' in text or 'E' in text):
            raise ValueError(f'the number {brief(text)} has more than {MAX_DIGITS} digits')
        if _INT.fullmatch(text):
            return int(text)
        return float(text)  # an overflowing exponent gives inf, refused by the field's check
    return text


def _plain(event: yaml.ScalarEvent) -> bool:
    """Tell a plain (unquoted) scalar; libyaml reports its style as '' and PyYAML as None."""
    return not event.style


def _where(event) -> str:
    mark = event.start_mark
    return f' (line {mark.line + 1}, column {mark.column + 1})' if mark else ''


class _Map:
    """A mapping being built: its dict and the key waiting for a value (None: a key is next)."""

    __slots__ = ('data', 'key')

    def __init__(self) -> None:
        self.data: dict = {}
        self.key: str | None = None


def _add(stack: list, value: Any, event) -> None:
    """Put ``value`` into the innermost container, as a mapping key or value or a list item."""
    top = stack[-1]
    if len(top.data if isinstance(top, _Map) else top) >= MAX_ITEMS:
        raise ValueError(f'a mapping or list may hold at most {MAX_ITEMS} entries{_where(event)}')
    if isinstance(top, list):
        top.append(value)
    elif top.key is not None:
        top.data[top.key] = value
        top.key = None
    elif not isinstance(value, str) or not isinstance(event, yaml.ScalarEvent):
        raise ValueError(f'every key must be a string, got {brief(value)}{_where(event)}')
    elif value == '<<' and _plain(event):
        raise ValueError(f'YAML merge keys (<<) are not accepted{_where(event)}')
    elif value in top.data:
        raise ValueError(f'duplicate key {brief(value)}{_where(event)}')
    else:
        top.key = value


class StrictParseError(ValueError):
    """
    A request text outside the strict language.

    ``partial`` holds the top-level mapping read before the problem (so that the request's id
    can still be answered).
    """

    def __init__(self, reason: str, partial: dict) -> None:
        super().__init__(reason)
        self.partial = partial


def _path(stack: list) -> str:
    """Where in the document the parser is, e.g. " in 'aero.wind[1]'"."""
    parts = []
    for item in stack:
        if isinstance(item, _Map):
            if item.key is None:
                break
            parts.append(('.' if parts else '') + item.key)
        else:
            parts.append(f'[{len(item)}]')
    return f" in '{''.join(parts)}'" if parts else ''


def load_strict(text: str) -> Any:
    """
    Parse ``text`` in the strict request language (module docstring).

    Returns plain data (dict, list, str, int, float, bool, None); an empty text gives ``{}``.
    Raises :class:`StrictParseError` (a ValueError) naming where and what; the parse stops at the
    first violation, so its cost is bounded by the text's size.
    """
    if text.lstrip()[:1] in ('{', '[', '"'):
        value = _load_json(text)  # JSON reads as json does (e.g. escaped surrogate pairs)
        if value is not None:
            return value
    stack: list = []
    result: Any = None
    documents = 0
    try:
        for event in yaml.parse(text, Loader=_Parser):
            if isinstance(
                event, (yaml.StreamStartEvent, yaml.StreamEndEvent, yaml.DocumentEndEvent)
            ):
                continue
            if isinstance(event, yaml.DocumentStartEvent):
                documents += 1
                if documents > 1:
                    raise ValueError('a request must be a single YAML/JSON document')
                continue
            if isinstance(event, yaml.AliasEvent) or getattr(event, 'anchor', None) is not None:
                raise ValueError(f'YAML anchors and aliases are not accepted{_where(event)}')
            if isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                done = stack.pop()
                value = done.data if isinstance(done, _Map) else done
            elif event.tag is not None and not (
                isinstance(event, yaml.CollectionStartEvent) and event.implicit
            ):
                raise ValueError(
                    f'YAML tags such as {brief(event.tag)} are not accepted{_where(event)}'
                )
            elif isinstance(event, yaml.ScalarEvent):
                value = _scalar(event)
            elif len(stack) >= MAX_DEPTH:
                raise ValueError(
                    f'the request is nested more than {MAX_DEPTH} levels deep{_where(event)}'
                )
            else:
                stack.append(_Map() if isinstance(event, yaml.MappingStartEvent) else [])
                continue
            if stack:
                _add(stack, value, event)
            else:
                result = value
    except (ValueError, yaml.YAMLError, RecursionError) as exc:
        partial = stack[0].data if stack and isinstance(stack[0], _Map) else {}
        if isinstance(exc, yaml.YAMLError):
            where = getattr(exc, 'problem_mark', None)
            at = f' at line {where.line + 1}, column {where.column + 1}' if where else ''
            problem = getattr(exc, 'problem', None) or type(exc).__name__
            reason = f'malformed YAML/JSON{at}: {problem}'
        elif isinstance(exc, RecursionError):
            reason = 'malformed YAML/JSON: nested too deeply'
        else:
            reason = str(exc)
        raise StrictParseError(reason + _path(stack), partial) from None
    return {} if result is None else result


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
        raise RequestError(
            made_up_id(),
            f'the request must be a mapping of release keys, got {type(data).__name__}',
        )
    try:
        request_id = check_id(data.pop('id')) if 'id' in data else made_up_id()
    except ValueError as exc:
        raise RequestError(made_up_id(), str(exc)) from None
    return request_id, data


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


class _NotStrict(Exception):
    """Raised inside :func:`_load_json` for JSON outside the strict language."""


def _json_pairs(pairs: list) -> dict:
    if len(pairs) > MAX_ITEMS or len({key for key, _ in pairs}) != len(pairs):
        raise _NotStrict
    return dict(pairs)


def _json_number(text: str) -> float | int:
    if sum(c.isdigit() for c in text) > MAX_DIGITS and 'e' not in text.lower():
        raise _NotStrict
    return int(text) if _INT.fullmatch(text) else float(text)


def _json_constant(_name: str) -> None:
    raise _NotStrict  # NaN, Infinity


def _within_limits(value: Any, depth: int = 0) -> bool:
    if isinstance(value, (dict, list)):
        items = value.values() if isinstance(value, dict) else value
        return (
            depth < MAX_DEPTH
            and len(value) <= MAX_ITEMS
            and all(_within_limits(v, depth + 1) for v in items)
        )
    return True


def _load_json(text: str) -> Any:
    """
    Parse strict JSON; None when the text is not JSON within the language's limits.

    The YAML path then reads it, or says precisely what is wrong.
    """
    try:
        value = json.loads(
            text,
            object_pairs_hook=_json_pairs,
            parse_int=_json_number,
            parse_float=_json_number,
            parse_constant=_json_constant,
        )
    except (_NotStrict, ValueError, RecursionError):
        return None
    return value if _within_limits(value) and value is not None else None


def _recovered_id(partial: dict) -> str:
    """Return the id of a request not readable to its end, if its valid 'id' came first."""
    try:
        return check_id(partial['id'])
    except (KeyError, ValueError):
        return made_up_id()


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


@dataclass(frozen=True)
class FlightOrder:
    """
    What the simulator needs to fly a ball: ids, ball, model, moment and initial state.

    ``request_id`` is the client's id; ``order_id`` names this hand-off uniquely (the
    simulator's acknowledgement carries it), empty for orders that bring none.
    """

    request_id: str
    ball_name: str
    ball_params: dict
    model: str
    moment: str
    initial: InitialState
    aero: dict = field(default_factory=dict)
    order_id: str = ''

    def ball(self) -> BallPreset:
        return get_preset(self.ball_name, self.ball_params)

    def flight(self, step: float, model: str | None = None) -> Flight:
        """
        Return the Flight this order means (``model`` overrides the ordered one).

        Raises ValueError (ReleaseError) when it cannot be flown with this ``step`` [s].
        """
        model = model or self.model
        aero = AeroModel.from_mapping(self.aero) if model == 'full' else None
        return Flight(self.ball(), self.initial, model, self.moment, step, aero)

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
        Inverse of :meth:`to_json`: the one validation of a hand-off (raises ValueError).

        The release node applies it to the text it sends and the simulator to the text it
        receives, so both judge an order by the same rules.
        """
        if not isinstance(text, str) or len(text.encode('utf-8', errors='replace')) > max_bytes:
            raise ValueError(f'a flight order must be JSON text of at most {max_bytes} bytes')
        data = load_strict(text)
        if not isinstance(data, dict):
            raise ValueError('a flight order must be a JSON object')
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
        request_id = check_id(data['id'])
        order_id = check_id(data['order']) if 'order' in data else ''
        ball = data.get('ball', 'american')
        model = data.get('model', 'paper')
        moment = data.get('moment', 'linear')
        if model not in MODELS:
            raise ValueError(f"'model' must be one of {', '.join(MODELS)}, got {brief(model)}")
        if moment not in MOMENT_CURVES:
            raise ValueError(
                f"'moment' must be one of {', '.join(MOMENT_CURVES)}, got {brief(moment)}"
            )
        ball_params = data.get('ball_params') or {}
        aero = data.get('aero') or {}
        for key, value in (('ball_params', ball_params), ('aero', aero)):
            if not isinstance(value, dict):
                raise ValueError(f"'{key}' must be a mapping, got {brief(value)}")
        if aero and model != 'full':
            raise ValueError("'aero' settings need model: full")
        get_preset(ball, ball_params)
        AeroModel.from_mapping(aero)
        initial = InitialState.from_rigid_body(
            _vector(data, 'position', 3),
            _vector(data, 'velocity', 3),
            _vector(data, 'orientation', 4),
            _vector(data, 'angular_velocity', 3),
        )
        return FlightOrder(request_id, ball, ball_params, model, moment, initial, aero, order_id)


def flight_summary(times: np.ndarray, positions: np.ndarray, landed: bool) -> dict[str, float]:
    """Return time_of_flight [s], range [m] (horizontal, from the release), apex height [m]."""
    horizontal = positions[-1, :2] - positions[0, :2]
    return {
        'time_of_flight': float(times[-1]) if landed else math.nan,
        'range': float(np.hypot(*horizontal)) if landed else math.nan,
        'apex_height': float(np.max(positions[:, 2])),
    }
