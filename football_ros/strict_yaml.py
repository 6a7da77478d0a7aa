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
A strict reader of YAML/JSON requests: the JSON-compatible subset of YAML, decided in bounded time.

Values are plain scalars, flow or block mappings and sequences, nested at most ``MAX_DEPTH``
levels. Scalars read as JSON reads them: ``true``/``false``, ``null``/``~``, decimal numbers
(``12``, ``-3.5``, ``1e3``); anything else (``0x14``, ``2_0``, ``.inf``, ``yes``) is a string.
Tags (``!!float``, ``!!binary``, ...), anchors, aliases, merge keys (``<<``), duplicate keys and
non-string keys are rejected, and so are mappings or lists of more than ``MAX_ITEMS`` entries
and numbers of more than ``MAX_DIGITS`` digits. libyaml's event parser is stopped at the first
violation, so the cost is bounded by the text's size. A library of its own: it imports nothing
from the package.
"""

from __future__ import annotations

import json
import re
from typing import Any

import yaml

MAX_DEPTH = 4
"""Nesting levels a request may use: request -> aero -> wind list needs 3."""
MAX_ITEMS = 64
"""Entries a mapping or items a list may hold (a release has 15 keys; lists hold 3 or 4)."""
MAX_ECHO = 60
"""Characters of a user's value echoed in an error message."""
MAX_DIGITS = 40
"""Digits a number may have (longer ones are refused before any conversion)."""
_Parser = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)  # libyaml when available


def brief(value: Any, limit: int = MAX_ECHO) -> str:
    """Return repr of a value cut to ``limit`` characters, for error messages."""
    text = repr(value) if not isinstance(value, str) else repr(value[: limit + 1])
    return text if len(text) <= limit else text[: limit - 3] + '...'


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

    Returns plain data (dict, list, str, int, float, bool, None); an empty text gives None.
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
    return result


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
