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

"""Throw-v0 and its vector env: gymnasium's checks, physics against Flight, seeds, bad input."""

import itertools
import math

from football_ros.envs import action_bounds, ACTION_KEYS, THROW_ID, ThrowTask
from football_ros.physics import Flight, Release
from football_ros.physics.release import LIMITS
import gymnasium as gym
from gymnasium.utils.env_checker import check_env
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

NOMINAL = np.array([21.0, 30.0, 0.0, 600.0, 0.0, 0.0, 0.0, 0.0])


def make_vec(n, **options):
    return gym.make_vec(THROW_ID, num_envs=n, vectorization_mode='vector_entry_point', **options)


def test_check_env_and_spaces_from_the_release_rules():
    env = gym.make(THROW_ID, receiver_speed=5.0, wind_speed=4.0)
    check_env(env.unwrapped, skip_render_check=True)
    low, high = env.action_space.low, env.action_space.high
    assert env.observation_space.shape == (7,)
    assert low[0] == LIMITS['speed'][0] + 4.0 and high[0] == LIMITS['speed'][1]
    for key in ('elevation_deg', 'azimuth_deg', 'spin_rpm'):
        i = ACTION_KEYS.index(key)
        assert (low[i], high[i]) == LIMITS[key]
    assert high[ACTION_KEYS.index('alpha0_deg')] == pytest.approx(45.0, abs=1e-12)
    assert high[ACTION_KEYS.index('beta_rate_deg_s')] == pytest.approx(3600.0 / math.sqrt(2))


def test_every_corner_of_the_action_box_is_a_valid_release():
    low, high = action_bounds()
    shrink = 1e-9 * (high - low)  # the combined rules are met with equality at the corners
    for corner in itertools.product(*zip(low + shrink, high - shrink)):
        Release(**dict(zip(ACTION_KEYS, corner)), position=(0.0, 0.0, 1.8))  # raises if not


def test_miss_and_arrival_match_an_independent_flight():
    """No noise, wind and a receiver: the batch kernel's frame shifts vs Flight in the wind."""
    task = {'release_noise': 0.0, 'receiver_speed': 3.0, 'wind_speed': 6.0,
            'target_distance': (30, 45)}
    env = gym.make(THROW_ID, **task).unwrapped
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        action = NOMINAL + [0.0, 5.0 * seed, 3.0 * seed, 0.0, 2.0, -1.0, 20.0, 0.0]
        _, reward, terminated, _, info = env.step(action)
        target, receiver, wind = obs[:3], obs[3:5], obs[5:7]
        release = Release(**dict(zip(ACTION_KEYS, action)), position=(0.0, 0.0, 1.8),
                          model='full', aero={'wind': [wind[0], wind[1], 0.0]})
        path = Flight.from_release(release, 0.0005).simulate(1000.0, 15.0, ground=target[2])
        t = path.times[-1]
        land = path.positions[-1, :2]
        miss = np.hypot(*(land - (target[:2] + receiver * t)))
        assert terminated and path.landed
        assert info['arrival_time'] == pytest.approx(t, abs=1e-4)
        assert info['miss'] == pytest.approx(miss, abs=2e-3)
        assert reward == pytest.approx(-miss, abs=2e-3)
        assert 0.0 < info['wobble_deg'] < 90.0


def test_noise_spreads_the_landings_as_the_sigmas_say():
    """Speed noise alone (others zero): the range spread is dR/dv times sigma_v."""
    n = 4096
    opts = {'target_distance': (40.0, 40.0), 'target_bearing_deg': (0.0, 0.0),
            'target_height': (1.8, 1.8)}
    quiet = make_vec(n, release_noise=0.0, **opts)
    quiet.reset(seed=0)
    speeds = NOMINAL[0] + np.array([-0.1, 0.1])
    misses = []
    for v in speeds:
        misses.append(quiet.step(np.tile(NOMINAL * 0 + [v, *NOMINAL[1:]], (n, 1)))[4]['miss'][0])
    noisy = make_vec(n, release_noise=1.0, **opts)
    noisy.reset(seed=1)
    _, reward, done, _, info = noisy.step(np.tile(NOMINAL, (n, 1)))
    assert done.all() and np.isfinite(reward).all()
    assert np.all(reward <= 0.0)
    # The nominal falls short of 40 m, so the miss grows as the speed falls.
    assert misses[0] > misses[1]
    spread = np.std(info['miss'])
    assert 0.5 < spread < 5.0


def test_seeded_resets_and_steps_repeat_bit_for_bit():
    def run(env_maker, seed):
        env = env_maker()
        out = []
        obs, _ = env.reset(seed=seed)
        out.append(obs)
        for k in range(3):
            action = NOMINAL + [k, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            if hasattr(env, 'num_envs'):
                action = np.tile(action, (env.num_envs, 1))
            obs, reward, *_, info = env.step(action)
            out += [np.atleast_1d(obs), np.atleast_1d(reward), np.atleast_1d(info['miss'])]
            if not hasattr(env, 'num_envs'):
                obs, _ = env.reset()
                out.append(obs)
        return out

    for maker in (lambda: gym.make(THROW_ID, wind_speed=3.0).unwrapped,
                  lambda: make_vec(64, receiver_speed=2.0)):
        a, b, c = run(maker, 7), run(maker, 7), run(maker, 8)
        assert all(np.array_equal(x, y) for x, y in zip(a, b))
        assert not np.array_equal(a[0], c[0])


@settings(max_examples=60, deadline=None)
@given(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                          st.floats(-5000, 5000)), min_size=8, max_size=8))
def test_hostile_actions_are_refused_clearly_or_flown(values):
    env = gym.make(THROW_ID).unwrapped
    env.reset(seed=0)
    action = np.array(values)
    low, high = env.action_space.low, env.action_space.high
    inside = np.isfinite(action) & (action >= low) & (action <= high)
    if inside.all():
        _, reward, *_ = env.step(action)
        assert math.isfinite(reward)
    else:
        bad = int(np.argmin(inside))
        with pytest.raises(ValueError, match=f"'{ACTION_KEYS[bad]}'"):
            env.step(action)


def test_bad_shapes_options_and_order_are_refused():
    env = gym.make(THROW_ID).unwrapped
    with pytest.raises(gym.error.ResetNeeded):
        env.step(NOMINAL)
    env.reset(seed=0)
    for bad in ([1.0, 2.0], 'fast', [[np.nan] * 8] * 2):
        with pytest.raises(ValueError, match='action'):
            env.step(bad)
    vec = make_vec(4)
    vec.reset(seed=0)
    actions = np.tile(NOMINAL, (4, 1))
    actions[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"action\[2\] 'elevation_deg' = nan must be finite"):
        vec.step(actions)
    with pytest.raises(ValueError, match='4 rows'):
        vec.step(np.tile(NOMINAL, (3, 1)))
    for options, field in (({'wind': 3}, 'unknown option'), ({'wind_speed': -1}, 'wind_speed'),
                           ({'target_distance': (50, 10)}, 'target_distance'),
                           ({'ball': 'soccer'}, 'soccer'), ({'num_envs': 0}, 'num_envs')):
        with pytest.raises(ValueError, match=field):
            ThrowTask.from_options(options) if 'num_envs' not in options else make_vec(0)


def test_the_example_learns_90_percent_within_1_m_at_40_m():
    """examples/learn_to_throw.py's cross-entropy method, seed 0, within its 1e5 throws."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / 'examples' / 'learn_to_throw.py'
    spec = importlib.util.spec_from_file_location('learn_to_throw', path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    release, curve = example.cross_entropy(0, 100_000)
    spent, hits, _ = curve[-1]
    assert spent <= 100_000 and hits >= 0.9
    # An independent check of the learned release: 2000 fresh throws, another seed.
    env = make_vec(2000, **example.TARGET)
    env.reset(seed=123)
    info = env.step(np.tile(release, (2000, 1)))[4]
    assert np.mean(info['miss'] <= 1.0) >= 0.85
