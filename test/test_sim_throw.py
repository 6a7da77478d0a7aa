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

"""SimThrow-v0 against the simulator: gymnasium's checks, states vs Flight, seeds, bad input."""

import math

from football_ros.envs import ACTION_KEYS, SIM_THROW_ID
from football_ros.physics import Flight
from football_ros.physics.presets import get_preset
from football_ros.physics.release import InitialState
import gymnasium as gym
from gymnasium.utils.env_checker import check_env
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

pytest.importorskip('simulation_interfaces.srv', reason='simulation_interfaces not built')
from football_ros.envs.sim_throw import find_services, release_message  # noqa: E402, I100

NOMINAL = np.array([18.0, 30.0, 0.0, 600.0, 2.0, 0.0, 10.0, 0.0])
TARGET = {'target_distance': (20.0, 30.0), 'target_bearing_deg': (-10.0, 10.0),
          'target_height': (1.0, 1.8)}


def episode(env, seed):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    while True:
        obs, reward, terminated, truncated, info = env.step(NOMINAL)
        out.append(obs)
        if terminated or truncated:
            return out, reward, terminated, info


def test_sim_throw_checks_repeats_and_matches_the_offline_flight(start_node):
    start_node('simulator')
    env = gym.make(SIM_THROW_ID, **TARGET)  # services found by type
    try:
        check_env(env.unwrapped, skip_render_check=True)
        first, reward, terminated, info = episode(env, 5)
        again, reward_again, *_ = episode(env, 5)
        assert terminated and reward == -info['miss'] and reward_again == reward
        assert all(np.array_equal(a, b) for a, b in zip(first, again))  # bit for bit
        # Every observed state is the offline flight of the noisy release at k control steps.
        state = release_message((0.0, 0.0, 1.8), info['release'])
        p, q = state.pose.position, state.pose.orientation
        v, w = state.twist.linear, state.twist.angular
        initial = InitialState.from_rigid_body(
            [p.x, p.y, p.z], [v.x, v.y, v.z], [q.x, q.y, q.z, q.w], [w.x, w.y, w.z])
        flight = Flight(get_preset('american'), initial, 'paper', 'linear', 0.001)
        dt = env.unwrapped.dt
        target = first[0][:3]
        for k, obs in enumerate(first[1:], start=1):
            s = flight.sample(k * dt)
            want = np.concatenate((s.position, s.orientation, s.velocity, s.angular_velocity))
            np.testing.assert_allclose(obs[3:16], want, rtol=0, atol=1e-9)
            assert obs[16] == pytest.approx(k * dt)
        # The miss: where the ball crosses the target's plane (between the last two steps).
        above, below = first[-2][3:6], first[-1][3:6]
        u = (above[2] - target[2]) / (above[2] - below[2])
        miss = np.hypot(*(above[:2] + u * (below[:2] - above[:2]) - target[:2]))
        assert info['miss'] == pytest.approx(miss, abs=1e-9)
        assert above[2] > target[2] >= below[2]

        env.reset(seed=0)
        low, high = env.action_space.low, env.action_space.high

        @settings(max_examples=25, deadline=None)
        @given(st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=8,
                        max_size=8))
        def hostile(values):
            action = np.array(values)
            inside = np.isfinite(action) & (action >= low) & (action <= high)
            if inside.all():
                return
            with pytest.raises(ValueError, match=f"'{ACTION_KEYS[int(np.argmin(inside))]}'"):
                env.step(action)

        hostile()
        obs, *_ = env.step(NOMINAL)  # refusals threw nothing: the first valid step throws
        assert obs[16] == pytest.approx(dt) and math.isfinite(obs[9])
    finally:
        env.close()


def test_services_found_by_type_or_prefix_and_refusals_name_the_problem():
    kinds = ('SpawnEntity', 'DeleteEntity', 'GetEntityState', 'SetEntityState',
             'SetSimulationState', 'StepSimulation')

    def served(prefix):
        return [(f'{prefix}/{k.lower()}', [f'simulation_interfaces/srv/{k}']) for k in kinds]

    one = served('/sim_a') + [('/other/x', ['std_srvs/srv/Trigger'])]
    assert find_services(one, None)['step_simulation'] == '/sim_a/stepsimulation'
    two = one + served('/ns/sim_b')
    with pytest.raises(LookupError, match="give the simulator's prefix"):
        find_services(two, None)
    assert find_services(two, '/ns/sim_b/')['spawn_entity'] == '/ns/sim_b/spawnentity'
    with pytest.raises(LookupError, match='StepSimulation under /nowhere'):
        find_services(two, '/nowhere')
    for options, field in (({'wind_speed': 2.0}, 'wind_speed'),
                           ({'control_rate': 0}, 'control_rate'),
                           ({'simulator': 3}, 'simulator'), ({'uri': None}, 'uri')):
        with pytest.raises(ValueError, match=field):
            gym.make(SIM_THROW_ID, **options)
