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
A simulated camera: what a ball detector would report, seeded so that runs repeat.

Captures the ball's position at ``rate`` [Hz] (capture times k / rate after the release),
adds Gaussian noise (``noise`` [m], 1 sigma per axis), drops a capture with probability
``dropout``, replaces one by an outlier (uniform direction, ``outlier_size`` [m] away) with
probability ``outlier_rate`` and delivers it ``latency`` [s] after its capture. Deliveries wait
in a bounded queue sized from rate x latency (:func:`queue_depth`), so that a camera stepped
at least every :data:`QUEUE_DEPTH` frames drops none; beyond it the oldest is dropped first and
every loss is counted by reason (:attr:`Camera.counts`). Times are seconds on one clock (the
caller's); positions are (3,) [m] in ``field``.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass
import math
from typing import Callable

import numpy as np

QUEUE_DEPTH = 256
"""Frames of slack in the queue beyond those in flight (rate x latency): how many frames a
caller may go without stepping the camera before the oldest are dropped."""


def queue_depth(settings: 'CameraSettings') -> int:
    """Return the bound of the camera's queue: rate x latency frames plus QUEUE_DEPTH."""
    return int(math.ceil(settings.rate * settings.latency)) + QUEUE_DEPTH


LIMITS = {
    'rate': (0.0, 1000.0),
    'noise': (0.0, 10.0),
    'latency': (0.0, 5.0),
    'dropout': (0.0, 1.0),
    'outlier_rate': (0.0, 1.0),
    'outlier_size': (0.0, 1000.0),
}


def check_numbers(kind: str, settings: object, limits: dict) -> None:
    """
    Raise ValueError naming the first attribute of ``settings`` outside its ``limits``.

    Each attribute named in ``limits`` must be a finite number (not a bool) in [lo, hi]; where
    lo and hi are both ints (a count), an int.
    """
    for name, (lo, hi) in limits.items():
        value = getattr(settings, name)
        count = isinstance(lo, int) and isinstance(hi, int)
        if (
            isinstance(value, bool)
            or not isinstance(value, int if count else (int, float))
            or not math.isfinite(value)
            or not lo <= value <= hi
        ):
            what = 'an integer' if count else 'a number'
            raise ValueError(
                f"{kind} '{name}' must be {what} in [{lo:g}, {hi:g}], got {value!r}"
            )


@dataclass(frozen=True)
class CameraSettings:
    """
    Camera settings, validated against :data:`LIMITS`.

    rate [Hz] (0 = off), noise [m], latency [s], dropout and outlier_rate [probability per
    capture], outlier_size [m], seed (int). Validated against :data:`LIMITS`.
    """

    rate: float = 0.0
    noise: float = 0.02
    latency: float = 0.02
    dropout: float = 0.0
    outlier_rate: float = 0.0
    outlier_size: float = 2.0
    seed: int = 0

    def __post_init__(self) -> None:
        check_numbers('camera', self, LIMITS)
        if isinstance(self.seed, bool) or not isinstance(self.seed, int):
            raise ValueError(f"camera 'seed' must be an integer, got {self.seed!r}")


@dataclass(frozen=True)
class Observation:
    """
    One detection.

    Capture time ``stamp`` [s], ``position`` (3,) [m] in ``field``, the time it is delivered
    [s] (``stamp`` + latency) and whether it is an injected outlier.
    """

    stamp: float
    position: np.ndarray
    delivery: float
    outlier: bool = False


class Camera:
    """
    Seeded camera model; :meth:`capture` one position, or :meth:`step` along a flight.

    :attr:`counts` says what became of every frame: 'captured', 'delivered', 'dropout' (lost
    by the model's ``dropout``), 'queue_full' (the oldest waiting dropped: the camera was not
    stepped for more than :data:`QUEUE_DEPTH` frames) and 'flushed' (handed over by
    :meth:`flush` before their delivery time).
    """

    def __init__(self, settings: CameraSettings) -> None:
        self.settings = settings
        self._rng = np.random.default_rng(settings.seed)
        self.depth = queue_depth(settings)
        self._queue: collections.deque[Observation] = collections.deque()
        self.counts: collections.Counter = collections.Counter()
        self.restart(0.0)

    @property
    def waiting(self) -> int:
        """Observations captured and not yet delivered."""
        return len(self._queue)

    def flush(self) -> list[Observation]:
        """Return every observation still waiting (oldest first), before its delivery time."""
        out = list(self._queue)
        self._queue.clear()
        self.counts['flushed'] += len(out)
        self.counts['delivered'] += len(out)
        return out

    def restart(self, release_time: float) -> None:
        """
        Start a new flight released at ``release_time`` [s]: captures at release_time + k / rate.

        Observations still waiting are kept (they were captured).
        """
        self._release = float(release_time)
        self._next_k = 0

    def capture(self, stamp: float, position: np.ndarray) -> Observation | None:
        """
        Return the detection of the ball at ``position`` [m] captured at ``stamp`` [s].

        None when dropped.
        """
        s = self.settings
        draws = self._rng.random(2)
        noise = self._rng.normal(0.0, s.noise, 3)
        if draws[0] < s.dropout:
            return None
        measured = np.asarray(position, dtype=float) + noise
        outlier = bool(draws[1] < s.outlier_rate)
        if outlier:
            direction = self._rng.normal(size=3)
            measured = measured + s.outlier_size * direction / max(np.linalg.norm(direction), 1e-9)
        return Observation(stamp, measured, stamp + s.latency, outlier)

    def step(self, now: float, position_at: Callable[[float], np.ndarray]) -> list[Observation]:
        """
        Capture every frame due up to ``now`` [s] and return the observations now delivered.

        ``position_at(t)`` gives the ball at capture time t, called with non-decreasing t.
        The observations returned are those whose delivery time has come, oldest first.
        """
        rate = self.settings.rate
        if rate > 0.0:
            while True:
                t = self._release + self._next_k / rate
                if t > now + 1e-12:
                    break
                self._next_k += 1
                obs = self.capture(t, position_at(t))
                self.counts['captured'] += 1
                if obs is None:
                    self.counts['dropout'] += 1
                    continue
                if len(self._queue) >= self.depth:
                    self._queue.popleft()
                    self.counts['queue_full'] += 1
                self._queue.append(obs)
        out = []
        while self._queue and self._queue[0].delivery <= now + 1e-12:
            out.append(self._queue.popleft())
        self.counts['delivered'] += len(out)
        return out

    def record(self, end: float, position_at: Callable[[float], np.ndarray]) -> list[Observation]:
        """
        Return every observation delivered up to ``end`` [s], for an offline replay.

        :meth:`step` in strides of half :data:`QUEUE_DEPTH` frames, so that the bounded
        queue drops none (one :meth:`step` to a far ``now`` keeps only the newest
        :attr:`depth`, as a stalled camera would); the same observations as stepping frame by
        frame.
        """
        out = []
        rate = self.settings.rate
        if rate > 0.0:
            now = self._release + self._next_k / rate
            while now < end:
                now = min(now + 0.5 * QUEUE_DEPTH / rate, end)
                out += self.step(now, position_at)
        return out + self.step(end, position_at)
