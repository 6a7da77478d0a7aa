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
Gymnasium environments (the optional extra ``gym``), registered on import (docs/envs.md).

- ``football_ros/Throw-v0``: one step per throw, flown by the batch kernel; its native vector
  env through ``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``.
- ``football_ros/SimThrow-v0``: one throw stepped at a control rate through any
  simulation_interfaces simulator (ROS; imported only when made).
"""

import gymnasium

from .throws import action_bounds, ACTION_KEYS, ThrowTask

THROW_ID = 'football_ros/Throw-v0'
SIM_THROW_ID = 'football_ros/SimThrow-v0'

if THROW_ID not in gymnasium.registry:
    gymnasium.register(
        id=THROW_ID,
        entry_point='football_ros.envs.throw_env:ThrowEnv',
        vector_entry_point='football_ros.envs.throw_env:ThrowVectorEnv',
    )
if SIM_THROW_ID not in gymnasium.registry:
    gymnasium.register(id=SIM_THROW_ID, entry_point='football_ros.envs.sim_throw:SimThrowEnv')

__all__ = ['action_bounds', 'ACTION_KEYS', 'SIM_THROW_ID', 'THROW_ID', 'ThrowTask']
