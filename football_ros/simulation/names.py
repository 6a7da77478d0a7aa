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
Entity name filters (simulation_interfaces EntityFilters.filter) matched in linear time.

The standard calls the filter a regular expression; it is compiled by RE2 (``google-re2``),
whose automaton matches in time linear in the name whatever the pattern (no backtracking), and
whose memory is capped by ``MAX_PROGRAM_BYTES``. RE2 takes the common syntax (classes,
alternation, groups, counted repetition); it has no backreferences or lookaround, which are
refused with RE2's own message. Without google-re2 (an install that lacks it) the standard
library's ``re`` serves, with patterns that could backtrack (a quantified group, or more than
``MAX_UNBOUNDED`` unbounded repeats) refused.
"""

from __future__ import annotations

import re

MAX_FILTER_CHARS = 256
"""Longest name filter [characters]."""
MAX_PROGRAM_BYTES = 1 << 20
"""Memory RE2 may give one compiled filter [bytes]; a larger automaton is refused."""
MAX_UNBOUNDED = 3
"""Without RE2: most unbounded repeats (``*``, ``+``, ``{n,}``) in one filter."""

try:
    import re2
except ImportError:  # pragma: no cover - google-re2 is a dependency; a bare install falls back
    re2 = None

_QUANTIFIED_GROUP = re.compile(r'\)\s*[*+?{]')
_UNBOUNDED = re.compile(r'(?<!\\)[*+]|\{\d*,\}')


class FilterError(ValueError):
    """A filter that is not a regular expression this matcher takes (the text says why)."""


def compile_filter(pattern: str):
    """
    Return a matcher of ``pattern`` with ``search(name) -> match or None``, or None for ''.

    Raises FilterError for a non-string, an over-long or an invalid pattern.
    """
    if not isinstance(pattern, str):
        raise FilterError(f'filter must be a string, got {type(pattern).__name__}')
    if not pattern:
        return None
    if len(pattern) > MAX_FILTER_CHARS:
        raise FilterError(
            f'filter has {len(pattern)} characters, more than the {MAX_FILTER_CHARS} accepted'
        )
    if re2 is not None:
        options = re2.Options()
        options.log_errors = False
        options.max_mem = MAX_PROGRAM_BYTES
        try:
            return re2.compile(pattern, options)
        except re2.error as exc:
            raise FilterError(
                f'filter is not a regular expression RE2 takes: {_text(exc)}'
            ) from None
    if _QUANTIFIED_GROUP.search(pattern) or len(_UNBOUNDED.findall(pattern)) > MAX_UNBOUNDED:
        raise FilterError(
            'filter could backtrack (a quantified group, or more than '
            f'{MAX_UNBOUNDED} unbounded repeats) and google-re2 is not installed'
        )
    try:
        return re.compile(pattern)
    except (re.error, RecursionError, OverflowError) as exc:
        raise FilterError(f'filter is not a regular expression: {exc}') from None


def _text(exc: Exception) -> str:
    text = exc.args[0] if exc.args else str(exc)
    return text.decode(errors='replace') if isinstance(text, bytes) else str(text)
