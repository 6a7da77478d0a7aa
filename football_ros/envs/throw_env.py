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
``football_ros/Throw-v0``: one step per throw, and its native vector env on the batch kernel.

The keyword options are :class:`football_ros.envs.throws.ThrowTask`'s fields. Observation: the
target point [m] in ``field`` (then the receiver's velocity and the wind [m/s] when enabled);
action: the release (:data:`football_ros.envs.throws.ACTION_KEYS`, within
:func:`football_ros.envs.throws.action_bounds`); reward: minus the miss [m] (capped) minus the
wobble term; every episode ends after its one step (``terminated``). The info: ``miss`` [m],
``arrival_time`` [s], ``wobble_deg`` [deg], ``release`` (the noisy release flown).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
from gymnasium.error import ResetNeeded
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
import numpy as np

from .throws import check_actions, fly, noisy_releases, ThrowTask


def _spaces(task: ThrowTask) -> tuple[gym.spaces.Box, gym.spaces.Box]:
    obs_low, obs_high = task.observation_bounds()
    act_low, act_high = task.action_bounds()
    return (gym.spaces.Box(obs_low, obs_high, dtype=np.float64),
            gym.spaces.Box(act_low, act_high, dtype=np.float64))


class ThrowEnv(gym.Env):
    """One throw per episode (module docstring); options: ThrowTask's fields."""

    metadata: dict[str, Any] = {'render_modes': []}

    def __init__(self, **options: Any) -> None:
        self.task = ThrowTask.from_options(options)
        self.observation_space, self.action_space = _spaces(self.task)
        self._obs: np.ndarray | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Draw a new target; ``seed`` reseeds the targets and the release noise."""
        super().reset(seed=seed)
        self._obs = self.task.sample(self.np_random, 1)[0]
        return self._obs.copy(), {}

    def step(self, action):
        """Throw ``action``; ValueError (naming the component) for one out of bounds or NaN."""
        if self._obs is None:
            raise ResetNeeded('call reset() before step(): every throw is one episode')
        low, high = self.action_space.low, self.action_space.high
        actions = check_actions(action, low, high)
        if actions.shape[0] != 1:
            raise ValueError(f'action must be one release, got {actions.shape[0]}')
        obs = self._obs[None, :]
        releases = noisy_releases(self.task, actions, self.np_random)
        out = fly(self.task, obs, releases)
        self._obs = None
        info = {
            'miss': float(out.miss[0]),
            'arrival_time': float(out.arrival_time[0]),
            'wobble_deg': float(out.wobble_deg[0]),
            'release': releases[0].copy(),
        }
        return obs[0].copy(), float(out.reward[0]), True, False, info


class ThrowVectorEnv(VectorEnv):
    """
    ``num_envs`` throws per step in one batch-kernel call (options: ThrowTask's fields).

    Every step ends every episode; the next targets are drawn in the same step (autoreset
    mode SAME_STEP): the observation returned is the next targets', the thrown ones are in
    ``info['final_obs']``. The info's ``miss``, ``arrival_time``, ``wobble_deg`` are arrays.
    """

    metadata: dict[str, Any] = {'autoreset_mode': AutoresetMode.SAME_STEP, 'render_modes': []}

    def __init__(self, num_envs: int = 1024, **options: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or not (
                1 <= num_envs <= 1_000_000):
            raise ValueError(f"'num_envs' must be an integer in [1, 1e6], got {num_envs!r}")
        self.num_envs = num_envs
        self.task = ThrowTask.from_options(options)
        self.single_observation_space, self.single_action_space = _spaces(self.task)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._obs: np.ndarray | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Draw ``num_envs`` targets; ``seed`` (an int) reseeds targets and release noise."""
        if seed is not None:
            if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
                raise ValueError(f"'seed' must be a non-negative integer, got {seed!r}")
            self._np_random, self._np_random_seed = seeding.np_random(int(seed))
        self._obs = self.task.sample(self.np_random, self.num_envs)
        return self._obs.copy(), {}

    def step(self, actions):
        """Throw one release per env; ValueError names the first bad component and row."""
        if self._obs is None:
            raise ResetNeeded('call reset() before step()')
        low, high = self.single_action_space.low, self.single_action_space.high
        actions = check_actions(actions, low, high)
        if actions.shape[0] != self.num_envs:
            raise ValueError(f'actions must have {self.num_envs} rows, got {actions.shape[0]}')
        thrown = self._obs
        releases = noisy_releases(self.task, actions, self.np_random)
        out = fly(self.task, thrown, releases)
        self._obs = self.task.sample(self.np_random, self.num_envs)
        done = np.ones(self.num_envs, dtype=bool)
        info = {
            'miss': out.miss,
            'arrival_time': out.arrival_time,
            'wobble_deg': out.wobble_deg,
            'final_obs': thrown,
            '_final_obs': done,
        }
        return self._obs.copy(), out.reward, done, np.zeros(self.num_envs, dtype=bool), info
