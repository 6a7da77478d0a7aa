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
A measured flight as the fit takes it, checked: :class:`Track`.

Times [s] on any clock (the fit's release state is at the first), positions [m] in ``field``,
optionally each fix's own noise sigma [m] and spin-axis observations (unit vectors in
``field``; the sign is not needed). Every bad number raises ValueError naming the track and the
row it came from, so that a file reader can hand over its rows unchecked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_FIXES = 8
"""Fewest fixes of a track (each fix gives 3 numbers; a flight's release state has 10)."""
MIN_DURATION = 0.1
"""Shortest track [s]: less says nothing of the air's forces."""
MAX_DURATION = 30.0
"""Longest track [s] (a kick is in the air well under 10 s)."""
MAX_FIXES = 100_000
"""Most fixes of one track."""
MAX_COORDINATE = 1.0e4
"""Largest |coordinate| [m] of a fix."""
MAX_SIGMA = 10.0
"""Largest per-fix sigma [m]."""


@dataclass(frozen=True)
class Track:
    """
    One flight's fixes, checked on construction.

    ``times`` (K,) [s] strictly increasing; ``positions`` (K, 3) [m] in ``field``; ``sigma``
    (K,) [m] per fix or None (estimated or given by the fit); ``axes`` (K, 3) observed spin
    axes (unit, either sign; an all-NaN row = not observed) or None; ``name`` for messages;
    ``rows`` (K,) the row number of each fix in its file (default 1, 2, ...) and ``row_word``
    what messages call it ('line' for a text file).
    """

    times: np.ndarray
    positions: np.ndarray
    sigma: np.ndarray | None = None
    axes: np.ndarray | None = None
    name: str = 'track'
    rows: np.ndarray | None = None
    row_word: str = 'row'

    def __post_init__(self) -> None:
        times = np.asarray(self.times, dtype=float).reshape(-1)
        n = times.size
        rows = np.arange(1, n + 1) if self.rows is None else np.asarray(self.rows).reshape(-1)
        object.__setattr__(self, 'rows', rows)
        if rows.size != n:
            raise ValueError(f'{self.name}: {rows.size} row numbers for {n} fixes')
        if n < MIN_FIXES:
            raise ValueError(
                f'{self.name}: {n} fix(es); a flight needs at least {MIN_FIXES}'
            )
        if n > MAX_FIXES:
            raise ValueError(f'{self.name}: {n} fixes; at most {MAX_FIXES} per flight')
        object.__setattr__(self, 'times', times)
        object.__setattr__(self, 'positions', self._array('position', self.positions, (n, 3)))
        bad = ~np.isfinite(times)
        if bad.any():
            raise ValueError(f'{self._where(bad)}: time is not a finite number')
        steps = np.diff(times)
        if np.any(steps <= 0.0):
            k = int(np.flatnonzero(steps <= 0.0)[0]) + 1
            raise ValueError(
                f'{self.name} {self.row_word} {rows[k]}: time {times[k]:g} s is not after the '
                f"previous {self.row_word}'s {times[k - 1]:g} s (times must increase)"
            )
        duration = times[-1] - times[0]
        if duration < MIN_DURATION:
            raise ValueError(
                f'{self.name}: the fixes span {duration:.3g} s; a flight needs at least '
                f'{MIN_DURATION:g} s to say anything of the air'
            )
        if duration > MAX_DURATION:
            k = int(np.searchsorted(times, times[0] + MAX_DURATION, side='right'))
            raise ValueError(
                f'{self.name} {self.row_word} {rows[k]}: t = {times[k]:g} s is more than '
                f'{MAX_DURATION:g} s after the first fix (one flight per track)'
            )
        pos = self.positions
        bad = ~np.all(np.isfinite(pos), axis=1)
        if bad.any():
            raise ValueError(f'{self._where(bad)}: position is not three finite numbers')
        bad = np.any(np.abs(pos) > MAX_COORDINATE, axis=1)
        if bad.any():
            raise ValueError(
                f'{self._where(bad)}: a coordinate beyond +-{MAX_COORDINATE:g} m'
            )
        if self.sigma is not None:
            sigma = self._array('sigma', self.sigma, (n,))
            bad = ~(np.isfinite(sigma) & (sigma > 0.0) & (sigma <= MAX_SIGMA))
            if bad.any():
                raise ValueError(
                    f'{self._where(bad)}: sigma must be in (0, {MAX_SIGMA:g}] m, got '
                    f'{sigma[np.flatnonzero(bad)[0]]!r}'
                )
            object.__setattr__(self, 'sigma', sigma)
        if self.axes is not None:
            axes = self._array('axis', self.axes, (n, 3))
            missing = np.all(np.isnan(axes), axis=1)
            norm = np.linalg.norm(np.where(missing[:, None], 1.0, axes), axis=1)
            bad = ~missing & ~(np.isfinite(norm) & (norm > 0.5) & (norm < 2.0))
            if bad.any():
                raise ValueError(
                    f'{self._where(bad)}: spin axis must be three finite numbers of length '
                    f'about 1 (or all three missing)'
                )
            if missing.all():
                axes = None
            else:
                axes = axes / norm[:, None]
            object.__setattr__(self, 'axes', axes)

    def _array(self, what: str, value, shape: tuple[int, ...]) -> np.ndarray:
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f'{self.name}: {what} values are not numbers') from None
        if arr.shape != shape:
            raise ValueError(f'{self.name}: {what} has shape {arr.shape}, expected {shape}')
        return arr

    def _where(self, bad: np.ndarray) -> str:
        return f'{self.name} {self.row_word} {self.rows[int(np.flatnonzero(bad)[0])]}'

    @property
    def observed_axes(self) -> np.ndarray:
        """Return the indices of the fixes with an observed axis."""
        if self.axes is None:
            return np.zeros(0, dtype=int)
        return np.flatnonzero(~np.isnan(self.axes[:, 0]))

    @property
    def duration(self) -> float:
        """Time from the first fix to the last [s]."""
        return float(self.times[-1] - self.times[0])
