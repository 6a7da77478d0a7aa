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
Several balls at once: one :class:`~.tracker.FlightTracker` per ball, fixes routed by gate.

Each live track is a FlightTracker holding one throw, with an id (1, 2, ... in order of start,
never reused). A fix goes to the live track whose predicted position it is nearest to
(squared Mahalanobis distance of a ballistic extrapolation of the estimate, with the
aerodynamic acceleration's reach as extra variance) within the gate; a fix near no track goes
to the initiator, a FlightTracker without a throw whose start-up buffer (a consensus arc,
robust to clutter, to the other balls and to wild stamps) starts the next track. A track ends
when it lands or when no fix reached it for ``max_gap`` [s] of the fixes' clock (lost); at
most ``max_tracks`` live at once (the oldest is ended for a new one). With ``carry_over`` the
drag and lift scales (and the wind) learnt by a throw that landed are the next throw's prior.
Times [s] are on the observations' clock; a clock that jumps back ends every track (the
initiator resets its time base and starts the next throw on the new clock).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from .measurement import Measurement, position_fix
from .tracker import FlightTracker, TrackerSettings, UpdateResult
from ..physics import dynamics as dyn

AERO_REACH = 15.0
"""Aerodynamic acceleration [m/s^2] a ball may have beyond gravity (drag of a fast throw)."""
NO_START_AFTER = 1.0
"""Span [s] of the fixes' clock over which fixes arrived, no track live, before a 'no_start'
event says why no throw started (once until a throw starts)."""


@dataclass(frozen=True)
class TrackEvent:
    """
    A track event: ``kind``, its track id, why, at ``time`` [s].

    'started', 'ended' (why: landed, lost, replaced by a new throw, ...), or 'no_start' (id
    0): fixes kept arriving for :data:`NO_START_AFTER` with no track live and none started.
    """

    kind: str
    track_id: int
    reason: str
    time: float


class MultiTracker:
    """Track several balls; :meth:`update` returns the track id a fix went to (or None)."""

    def __init__(
        self,
        settings: TrackerSettings | None = None,
        max_tracks: int = 4,
        carry_over: bool = False,
    ) -> None:
        if isinstance(max_tracks, bool) or not isinstance(max_tracks, int) or not (
            1 <= max_tracks <= 64
        ):
            raise ValueError(f"'max_tracks' must be an integer in [1, 64], got {max_tracks!r}")
        self.settings = settings or TrackerSettings()
        self.max_tracks = max_tracks
        self.carry_over = bool(carry_over)
        self.tracks: dict[int, FlightTracker] = {}
        self.events: list[TrackEvent] = []
        self._initiator = FlightTracker(self.settings)
        self._next_id = 1
        self._newest = -math.inf
        self._idle: tuple[float, bool] | None = None  # (first idle fix's stamp, told)
        self._g = float(self._initiator.params[dyn.P_GRAVITY])
        self.taken_by: FlightTracker | None = None
        """The filter that took the last fix (kept after its track ended, for its outputs)."""

    def reset_time_base(self) -> bool:
        """
        End every track and reset the initiator's time base (the clock jumped back).

        Returns False if there was nothing to reset (no fix used yet).
        """
        if not math.isfinite(self._newest) and not self.tracks:
            return False
        for tid in list(self.tracks):
            self._end(tid, 'the clock jumped back', self._newest)
        self._initiator.reset_time_base()
        self._newest = -math.inf
        return True

    @property
    def ball(self):
        """Return the ball the filters assume (of the preset ``settings.ball``)."""
        return self._initiator.ball

    def update(
        self, stamp: float, position, now: float | None = None, covariance=None
    ) -> tuple[int | None, UpdateResult]:
        """
        Route one fix (capture time ``stamp`` [s], ``position`` (3,) [m]) and process it.

        ``covariance`` (3, 3) [m^2] of the fix in ``field`` (None: the settings' noise).
        Returns (id of the track that took it or started from it, or None; the result).
        :attr:`events` gets the tracks started and ended meanwhile (the caller empties it).
        """
        try:
            meas = position_fix(position, covariance, self.settings.noise)
        except (TypeError, ValueError) as exc:
            field_name = 'covariance' if covariance is not None else 'position'
            return None, UpdateResult('invalid', f'{field_name}: {exc}')
        return self.observe(stamp, meas, now)

    def observe(
        self, stamp: float, meas: Measurement, now: float | None = None
    ) -> tuple[int | None, UpdateResult]:
        """Route one fix of any measurement model (:mod:`.measurement`): :meth:`update`."""
        try:
            t = float(stamp)
        except (TypeError, ValueError):
            return None, UpdateResult('invalid', 'stamp must be a number')
        if not isinstance(meas, Measurement):
            return None, UpdateResult('invalid', 'not a measurement')
        guess = meas.position_guess()
        if not math.isfinite(t):
            return None, UpdateResult('invalid', 'non-finite stamp')
        if (guess is not None and np.any(np.abs(guess) > 1e5)) or abs(t) > 1e12:
            return None, UpdateResult('invalid', 'position beyond 100 km or absurd stamp')
        track_id = self._nearest(t, meas)
        if track_id is not None:
            self._initiator.frame_stamps.append(t)  # the camera's rate, for the next start
            tracker = self.taken_by = self.tracks[track_id]
            result = tracker.observe(t, meas, now)
            if result.used:
                self._newest = max(self._newest, t)
                self._end_silent(self._newest)
            if result.status == 'started':  # the track's own restart: a new throw in it
                why = tracker.restart_reason
                self._end(track_id, 'replaced by a new throw' + (f': {why}' if why else ''), t)
                track_id = self._adopt(tracker, t)
            elif result.landed:
                self._end(track_id, 'landed', t)
                if self.carry_over:  # the same ball again in the same air
                    self._initiator.learn_from(tracker)
            return track_id, result
        self.taken_by = self._initiator
        result = self._initiator.observe(t, meas, now)
        if result.status == 'candidate' and not self.tracks:
            self._no_start(t, result.reason)
        if result.status == 'started':
            self._idle = None
            if result.reason:  # the clock jumped back: every track belongs to the old clock
                for tid in list(self.tracks):
                    self._end(tid, result.reason, t)
                self._newest = t
            self._newest = max(self._newest, t)
            self._end_silent(self._newest)
            new_id = self._adopt(self._initiator, t)
            return new_id, result
        return None, result

    def _no_start(self, t: float, reason: str) -> None:
        """Note an idle fix; once fixes span :data:`NO_START_AFTER`, say why none started."""
        if self._idle is None or not 0.0 <= t - self._idle[0] <= 10.0 * NO_START_AFTER:
            self._idle = (t, False)  # the first, or a stamp far from the others: start again
            return
        first, told = self._idle
        if told or t - first < NO_START_AFTER:
            return
        stamps = [c[0] for c in self._initiator._candidates]
        gaps = np.diff(np.unique(stamps))
        every = f'; fixes every {1e3 * float(np.median(gaps)):.0f} ms' if gaps.size else ''
        self.events.append(TrackEvent(
            'no_start', 0, f'fixes for {t - first:.1f} s and no throw started: {reason}{every}', t
        ))
        self._idle = (first, True)

    def _adopt(self, tracker: FlightTracker, t: float) -> int:
        """Make ``tracker`` (holding a fresh throw) a live track; a new initiator if it was."""
        if tracker is self._initiator:
            fresh = FlightTracker(self.settings)
            fresh.learned = tracker.learned
            fresh.frame_stamps.extend(tracker.frame_stamps)
            fresh._candidates.extend(tracker._candidates)  # the other balls' fixes
            tracker._candidates.clear()
            self._initiator = fresh
        while len(self.tracks) >= self.max_tracks:
            self._end(min(self.tracks), 'too many tracks: the oldest ended', t)
        track_id = self._next_id
        self._next_id += 1
        self.tracks[track_id] = tracker
        self.events.append(TrackEvent('started', track_id, '', t))
        return track_id

    def _end(self, track_id: int, reason: str, t: float) -> None:
        if self.tracks.pop(track_id, None) is not None:
            self.events.append(TrackEvent('ended', track_id, reason, t))
            self._idle = None

    def _end_silent(self, t: float) -> None:
        """
        End the tracks no fix reached for ``max_gap`` before ``t`` (lost).

        ``t`` is the newest fix used: a wild stamp, which no track takes, ends none.
        """
        for tid, tr in list(self.tracks.items()):
            if tr.track is None or t - tr.track.t > self.settings.max_gap:
                self._end(tid, 'lost: no fix for max_gap', t)

    def _nearest(self, t: float, meas: Measurement) -> int | None:
        """
        Id of the live track whose gate holds the fix, the nearest; None if none.

        The innovation in the measurement's own space: its model linearised at the predicted
        position (a central difference; exact for a position).
        """
        best, best_d2 = None, self.settings.gate
        for tid, tr in self.tracks.items():
            est = tr.estimate
            if est is None or tr.landed:
                continue
            t0, x, P = est
            dt = t - t0
            if abs(dt) > self.settings.max_gap:
                continue
            pred = x[:3] + x[3:6] * dt - 0.5 * self._g * dt * dt * np.array([0.0, 0.0, 1.0])
            J = np.hstack([np.eye(3), dt * np.eye(3)])
            cov = J @ P[:6, :6] @ J.T + (0.5 * AERO_REACH * dt * dt) ** 2 * np.eye(3)
            try:
                with np.errstate(all='ignore'):
                    H = _jacobian(meas, pred)
                    S = H @ cov @ H.T + meas.R
                    nu = meas.z - meas.predict(pred[None, :])[0]
                    d2 = float(nu @ np.linalg.solve(S, nu))
            except (np.linalg.LinAlgError, ValueError):
                continue
            if not math.isfinite(d2):
                continue
            if d2 <= best_d2:
                best, best_d2 = tid, d2
        return best


def _jacobian(meas: Measurement, r: np.ndarray, step: float = 1e-3) -> np.ndarray:
    """d(predict)/d(position) (m, 3) at ``r`` [m], central differences of ``step`` [m]."""
    pts = np.vstack([r + step * np.eye(3), r - step * np.eye(3)])
    images = meas.predict(pts)
    return ((images[:3] - images[3:]) / (2.0 * step)).T
