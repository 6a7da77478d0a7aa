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
Throwing tasks without gymnasium or ROS: the action's bounds, its checks, the targets, the flight.

A throw: the thrower's hand at (0, 0, ``release_height``) in ``field``; a target point drawn at a
distance and bearing from the thrower (optionally a receiver moving at constant horizontal
velocity from it, and a uniform horizontal wind); the action is a release (:data:`ACTION_KEYS`,
the release rules' keys in their units); the release is perturbed by Gaussian release noise
(``release_noise`` times :data:`football_ros.physics.release.ERROR_SIGMAS`, clipped to the
action's bounds) and flown in the full model by the batch kernel
(:func:`football_ros.physics.batch.simulate_batch`) until it crosses the target's horizontal
plane going down. The miss [m] is the horizontal distance there to the receiver (the target
point moved by the receiver's velocity times the arrival time).

Many throws with different winds and target heights share one kernel call: the flight is
computed in the frame moving with the wind (air-relative velocity, the same loads) and shifted
down by the target height (a uniform field), then moved back.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from typing import Any, Mapping

import numpy as np

from ..physics.aero import AeroModel
from ..physics.batch import simulate_batch
from ..physics.presets import get_preset
from ..physics.release import ERROR_SIGMAS, LIMITS, release_states, STATE_KEYS

ACTION_KEYS = STATE_KEYS
"""The action's components, in order: speed [m/s], elevation_deg, azimuth_deg [deg], spin_rpm
[rev/min], alpha0_deg, beta0_deg [deg], alpha_rate_deg_s, beta_rate_deg_s [deg/s]."""

MAX_TIME = 15.0
"""Longest flight [s] flown; a throw that has not crossed the target plane by then misses."""


def action_bounds(wind_speed: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """
    Return (low, high) of the action (:data:`ACTION_KEYS`), every corner a valid release.

    From :data:`football_ros.physics.release.LIMITS`: each key's range, narrowed where two keys
    combine. The axis offsets to +-acos(sqrt(cos(max offset))) (45 deg), so that the total
    offset acos(cos alpha0 cos beta0) stays within LIMITS['axis_offset_deg']; the attitude rates
    to the transverse-rate limit / sqrt(2) (the two rates add in quadrature); the speed's lower
    end to LIMITS' lowest speed above ``wind_speed`` [m/s], so that every release moves through
    the air.
    """
    offset = math.degrees(math.acos(math.sqrt(math.cos(math.radians(
        LIMITS['axis_offset_deg'][1])))))
    rate = LIMITS['transverse_rate_deg_s'][1] / math.sqrt(2.0)
    low, high = [], []
    for key in ACTION_KEYS:
        lo, hi = LIMITS[key]
        if key in ('alpha0_deg', 'beta0_deg'):
            lo, hi = max(lo, -offset), min(hi, offset)
        elif key in ('alpha_rate_deg_s', 'beta_rate_deg_s'):
            lo, hi = max(lo, -rate), min(hi, rate)
        elif key == 'speed':
            lo = lo + wind_speed
        low.append(lo)
        high.append(hi)
    return np.array(low), np.array(high)


def check_actions(actions: Any, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """
    Return ``actions`` as an (N, 8) float array if every one is finite and within bounds.

    Raises ValueError naming the first bad component (key, row, value and the bounds).
    """
    try:
        arr = np.array(actions, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f'action must be numbers ({", ".join(ACTION_KEYS)}): {exc}') from None
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != len(ACTION_KEYS):
        raise ValueError(
            f'action must have {len(ACTION_KEYS)} components ({", ".join(ACTION_KEYS)}) per '
            f'throw, got shape {np.shape(actions)}'
        )
    bad = ~(np.isfinite(arr) & (arr >= low) & (arr <= high))
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        value = float(arr[row, col])
        where = f'action[{row}]' if arr.shape[0] > 1 else 'action'
        why = 'must be finite, in' if not math.isfinite(value) else 'is outside'
        raise ValueError(
            f"{where} '{ACTION_KEYS[col]}' = {value!r} {why} "
            f'[{low[col]:g}, {high[col]:g}] (football_ros.envs.action_bounds)'
        )
    return arr


def _pair(name: str, value: Any, lo: float, hi: float) -> tuple[float, float]:
    ok = isinstance(value, (tuple, list)) and len(value) == 2
    a, b = (value if ok else (None, None))
    if not (ok and all(_number(x) for x in (a, b)) and lo <= a <= b <= hi):
        raise ValueError(f"'{name}' must be [low, high] with {lo:g} <= low <= high <= {hi:g}, "
                         f'got {value!r}')
    return float(a), float(b)


def _number(x: Any) -> bool:
    return not isinstance(x, bool) and isinstance(x, (int, float)) and math.isfinite(x)


def _scalar(name: str, value: Any, lo: float, hi: float) -> float:
    if not (_number(value) and lo <= value <= hi):
        raise ValueError(f"'{name}' must be a number in [{lo:g}, {hi:g}], got {value!r}")
    return float(value)


@dataclass(frozen=True)
class ThrowTask:
    """
    What is thrown at and how it is scored (SI units, angles in degrees; checked on creation).

    ball: preset name; release_height [m]: the hand's z; target_distance [m] and
    target_bearing_deg [deg, counter-clockwise from +x]: ranges the target point is drawn from
    (uniformly), target_height [m]: range of its z; receiver_speed [m/s]: largest speed of the
    receiver (0: a fixed target, and no receiver velocity in the observation); wind_speed [m/s]:
    largest horizontal wind (0: calm, and no wind in the observation); release_noise: scale of
    the release errors (1 = ERROR_SIGMAS); wobble_weight [1/deg]: reward per degree of the
    largest angle between axis and air velocity; miss_cap [m]: the largest miss counted.
    """

    ball: str = 'american'
    release_height: float = 1.8
    target_distance: tuple[float, float] = (10.0, 50.0)
    target_bearing_deg: tuple[float, float] = (-30.0, 30.0)
    target_height: tuple[float, float] = (0.5, 2.0)
    receiver_speed: float = 0.0
    wind_speed: float = 0.0
    release_noise: float = 1.0
    wobble_weight: float = 0.0
    miss_cap: float = 100.0

    def __post_init__(self) -> None:
        if not isinstance(self.ball, str):
            raise ValueError(f"'ball' must be a preset name, got {self.ball!r}")
        get_preset(self.ball)  # raises ValueError naming the known presets
        z_hi = LIMITS['position_z'][1]
        checks = {
            'release_height': lambda v: _scalar('release_height', v, 0.01, z_hi),
            'target_distance': lambda v: _pair('target_distance', v, 1.0, 200.0),
            'target_bearing_deg': lambda v: _pair('target_bearing_deg', v, -180.0, 180.0),
            'target_height': lambda v: _pair('target_height', v, 0.0, 100.0),
            'receiver_speed': lambda v: _scalar('receiver_speed', v, 0.0, 15.0),
            'wind_speed': lambda v: _scalar('wind_speed', v, 0.0, 20.0),
            'release_noise': lambda v: _scalar('release_noise', v, 0.0, 10.0),
            'wobble_weight': lambda v: _scalar('wobble_weight', v, 0.0, 100.0),
            'miss_cap': lambda v: _scalar('miss_cap', v, 0.01, 1000.0),
        }
        for name, check in checks.items():
            object.__setattr__(self, name, check(getattr(self, name)))

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> 'ThrowTask':
        """Build from keyword options; unknown names raise ValueError listing the known ones."""
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(options) - set(known))
        if unknown:
            raise ValueError(f'unknown option(s) {", ".join(map(repr, unknown))}; known: '
                             f'{", ".join(known)}')
        return cls(**options)

    def observation_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of the observation: target x, y, z [m], receiver, wind [m/s]."""
        d = self.target_distance[1]
        low = [-d, -d, self.target_height[0]]
        high = [d, d, self.target_height[1]]
        for speed in (self.receiver_speed, self.wind_speed):
            if speed > 0.0:
                low += [-speed, -speed]
                high += [speed, speed]
        return np.array(low), np.array(high)

    def action_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of the action: :func:`action_bounds` in this task's largest wind."""
        return action_bounds(self.wind_speed)

    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Draw ``n`` observations (targets, receiver velocities, winds) from ``rng``."""
        distance = rng.uniform(*self.target_distance, n)
        bearing = np.radians(rng.uniform(*self.target_bearing_deg, n))
        columns = [distance * np.cos(bearing), distance * np.sin(bearing),
                   rng.uniform(*self.target_height, n)]
        for speed in (self.receiver_speed, self.wind_speed):
            if speed > 0.0:
                magnitude = speed * np.sqrt(rng.uniform(0.0, 1.0, n))  # uniform over the disc
                heading = rng.uniform(-math.pi, math.pi, n)
                columns += [magnitude * np.cos(heading), magnitude * np.sin(heading)]
        return np.stack(columns, axis=1)

    def split(self, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(target (N, 3), receiver velocity (N, 2), wind (N, 2)) of observations."""
        target = observations[:, :3]
        zero = np.zeros((observations.shape[0], 2))
        column = 3
        parts = []
        for speed in (self.receiver_speed, self.wind_speed):
            if speed > 0.0:
                parts.append(observations[:, column:column + 2])
                column += 2
            else:
                parts.append(zero)
        return target, parts[0], parts[1]


@dataclass(frozen=True)
class Outcome:
    """
    Per-throw results of :func:`fly`.

    miss [m] (inf: never crossed the target plane going down), arrival_time [s] (nan then),
    wobble_deg [deg] (largest angle between axis and air velocity), reward.
    """

    miss: np.ndarray
    arrival_time: np.ndarray
    wobble_deg: np.ndarray
    reward: np.ndarray


def noisy_releases(task: ThrowTask, actions: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Actions (N, 8) plus release noise from ``rng``, clipped to the action's bounds."""
    if task.release_noise == 0.0:
        return actions
    sigmas = task.release_noise * np.array([ERROR_SIGMAS[k] for k in ACTION_KEYS])
    low, high = task.action_bounds()
    return np.clip(actions + sigmas * rng.standard_normal(actions.shape), low, high)


def flight_states(task: ThrowTask, observations: np.ndarray, releases: np.ndarray) -> dict:
    """
    Batch-kernel states of releases (N, 8) in the frame of each throw's wind and target plane.

    :func:`football_ros.physics.release.release_states` at the hand, its velocity made relative
    to the wind and its height to the target's (the kernel then flies in calm air down to z = 0).
    """
    target, _receiver, wind = task.split(observations)
    states = release_states(*releases.T, (0.0, 0.0, task.release_height))
    states['velocity'][:, :2] -= wind
    states['position'][:, 2] -= target[:, 2]
    return states


def fly(task: ThrowTask, observations: np.ndarray, releases: np.ndarray) -> Outcome:
    """
    Fly releases (N, 8), already noisy, at the observations' targets; score them.

    The reward: -min(miss, miss_cap) - wobble_weight * wobble_deg.
    """
    ball = get_preset(task.ball)
    states = flight_states(task, observations, releases)
    result = simulate_batch(ball, states, 'full', 'linear', AeroModel(), max_time=MAX_TIME,
                            ground=0.0)
    target, receiver, wind = task.split(observations)
    t = result.time_of_flight
    dx = result.landing_x + wind[:, 0] * t - (target[:, 0] + receiver[:, 0] * t)
    dy = result.landing_y + wind[:, 1] * t - (target[:, 1] + receiver[:, 1] * t)
    miss = np.hypot(dx, dy)
    landed = result.landed & np.isfinite(miss)
    miss = np.where(landed, miss, np.inf)
    wobble = np.degrees(result.max_delta)
    wobble = np.where(np.isfinite(wobble), wobble, 180.0)  # (never published non-finite)
    reward = -np.minimum(miss, task.miss_cap) - task.wobble_weight * wobble
    return Outcome(miss, np.where(landed, t, np.nan), wobble, reward)
