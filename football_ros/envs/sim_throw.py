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
``football_ros/SimThrow-v0``: one throw stepped at a control rate through simulation_interfaces.

Drives any simulator serving the standard services (this package's simulator by default, which
the user starts): it finds them by type (or under a given ``simulator`` prefix), pauses the
simulation, spawns one ball and reuses it for every episode. ``reset`` puts the ball at rest
at the hand (SetEntityState, zero twist) and draws a target; the first ``step`` throws the
action's release (release noise added: SetEntityState with the release's pose and twist),
every step then advances the simulation by 1 / ``control_rate`` seconds (StepSimulation of
``round(1 / (control_rate * sim_step))`` steps) and reads the ball (GetEntityState). Actions
after the first of an episode are checked and ignored (the ball is in flight); every step's
info has the ``release`` flown (the noisy one). The episode
ends when the ball crosses the target's horizontal plane going down (reward: minus the miss
[m] there, interpolated between the two control steps, capped) or is truncated after
:data:`football_ros.envs.throws.MAX_TIME` of flight (reward: minus the cap).

Observation: the target [m] (and the receiver's velocity [m/s] when enabled), the ball's
position [m], orientation (x, y, z, w), velocity [m/s] and angular velocity [rad/s] in the
simulator's world frame, and the time since the release [s].

What keeps a long-lived client from slowing down (docs/envs.md): one ball (entities never pile
up in the simulator, no endpoints made after the start), one executor with the node added
once and waited on with spin_once (not spin_until_future_complete, whose per-call done
callback piles up as executor tasks), one client per service made once, and a timed-out
request removed from its client.
"""

from __future__ import annotations

import math
import os
import time
from typing import Any

from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3
import gymnasium as gym
import numpy as np
import rclpy
from rclpy.executors import SingleThreadedExecutor
from simulation_interfaces.msg import EntityState, Result, SimulationState
from simulation_interfaces.srv import (
    DeleteEntity,
    GetEntityState,
    SetEntityState,
    SetSimulationState,
    SpawnEntity,
    StepSimulation,
)

from .throws import ACTION_KEYS, check_actions, MAX_TIME, noisy_releases, ThrowTask
from ..physics.frames import attitude_with_axis
from ..physics.release import release_states

SERVICES = {
    'spawn_entity': SpawnEntity,
    'delete_entity': DeleteEntity,
    'get_entity_state': GetEntityState,
    'set_entity_state': SetEntityState,
    'set_simulation_state': SetSimulationState,
    'step_simulation': StepSimulation,
}
"""The services used, by their standard snake-case names (found by type)."""
STATE_KEYS = ('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw', 'vx', 'vy', 'vz', 'wx', 'wy', 'wz')


def _type_name(srv_type) -> str:
    module = srv_type.__module__.split('.')[0]
    return f'{module}/srv/{srv_type.__name__}'


def find_services(names_and_types, prefix: str | None) -> dict[str, str]:
    """
    Return {standard name: service name} for :data:`SERVICES`, matched by type.

    ``names_and_types``: ``Node.get_service_names_and_types()``; ``prefix``: only services
    under it (e.g. ``/football_simulator``). Raises LookupError naming what is missing or
    ambiguous.
    """
    root = None if prefix is None else '/' + prefix.strip('/') + '/'
    found, missing = {}, []
    for key, srv_type in SERVICES.items():
        wanted = _type_name(srv_type)
        names = sorted(n for n, types in names_and_types if wanted in types
                       and (root is None or n.startswith(root)))
        if len(names) > 1:
            standard = [n for n in names if n.rsplit('/', 1)[-1] == key]
            if len(standard) != 1:
                raise LookupError(f'{len(names)} services of type {wanted} ({", ".join(names)}): '
                                  "give the simulator's prefix")
            names = standard
        if names:
            found[key] = names[0]
        else:
            missing.append(wanted)
    if missing:
        where = f' under {prefix}' if prefix else ''
        raise LookupError(f'no service of type {", ".join(missing)}{where}')
    return found


def release_message(position, releases: np.ndarray) -> EntityState:
    """Return the EntityState (world frame) of one release (ACTION_KEYS) from ``position``."""
    s = release_states(*releases.reshape(1, -1).T, position)
    omega = s['transverse_rate'][0] + s['spin'][0] * s['axis'][0]
    state = EntityState()
    state.pose = _pose(position, attitude_with_axis(s['axis'][0]))
    state.twist = Twist(linear=Vector3(**dict(zip('xyz', s['velocity'][0].tolist()))),
                        angular=Vector3(**dict(zip('xyz', omega.tolist()))))
    return state


def _pose(position, quaternion) -> Pose:
    return Pose(position=Point(**dict(zip('xyz', (float(p) for p in position)))),
                orientation=Quaternion(**dict(zip('xyzw', (float(q) for q in quaternion)))))


def _state_vector(state: EntityState) -> np.ndarray:
    p, q = state.pose.position, state.pose.orientation
    v, w = state.twist.linear, state.twist.angular
    out = np.array([p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z])
    if not np.isfinite(out).all():
        bad = STATE_KEYS[int(np.argmin(np.isfinite(out)))]
        raise RuntimeError(f"the simulator sent a non-finite entity state ('{bad}')")
    return out


class SimClient:
    """Calls to one simulator's services, each waited for on the client's own executor."""

    def __init__(self, prefix: str | None, timeout: float, discovery_timeout: float) -> None:
        self.timeout = timeout
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        try:
            self.node = rclpy.create_node(f'sim_throw_{os.getpid()}_{id(self):x}',
                                          context=self.context)
            self.executor = SingleThreadedExecutor(context=self.context)
            self.executor.add_node(self.node)
            self.names = self._discover(prefix, discovery_timeout)
            self.clients = {key: self.node.create_client(SERVICES[key], name)
                            for key, name in self.names.items()}
            for key, client in self.clients.items():
                if not client.wait_for_service(timeout_sec=discovery_timeout):
                    raise LookupError(f'service {self.names[key]} does not answer')
        except BaseException:
            self.close()
            raise

    def _discover(self, prefix: str | None, timeout: float) -> dict[str, str]:
        deadline = self.node.get_clock().now().nanoseconds + int(timeout * 1e9)
        while True:
            try:
                return find_services(self.node.get_service_names_and_types(), prefix)
            except LookupError:
                if self.node.get_clock().now().nanoseconds > deadline:
                    raise
            self.executor.spin_once(timeout_sec=0.1)

    def call(self, key: str, request, ok=(Result.RESULT_OK,)):
        """Return the response of service ``key``; RuntimeError on a timeout or a refusal."""
        client = self.clients[key]
        future = client.call_async(request)
        # spin_once, not spin_until_future_complete: that adds a done callback to the future,
        # which becomes an executor task per call that is never run, and the executor's task
        # list (walked on every wake-up) grows by one per call.
        deadline = time.monotonic() + self.timeout
        while not future.done() and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=max(0.0, deadline - time.monotonic()))
        if not future.done():
            client.remove_pending_request(future)
            raise TimeoutError(f'{self.names[key]}: no answer in {self.timeout:g} s')
        response = future.result()
        code = response.result.result
        if code not in ok:
            raise RuntimeError(f'{self.names[key]} refused ({code}): '
                               f'{response.result.error_message}')
        return response

    def close(self) -> None:
        """Destroy the node and shut the client's context down."""
        if getattr(self, 'executor', None) is not None:
            self.executor.shutdown()
        if getattr(self, 'node', None) is not None:
            self.node.destroy_node()
        if self.context.ok():
            rclpy.shutdown(context=self.context)


class SimThrowEnv(gym.Env):
    """
    One throw per episode through a simulation_interfaces simulator (module docstring).

    Options: ``simulator`` (service prefix; None: found by type), ``uri`` of the ball
    (``football_ros://american``), ``control_rate`` [Hz] (50), ``sim_step`` [s] (the
    simulator's step, 0.001: this package's default integration_step), ``timeout`` [s] per call,
    ``discovery_timeout`` [s], and ThrowTask's fields except ``wind_speed`` (the wind is the
    simulator's) and ``wobble_weight``.
    """

    metadata: dict[str, Any] = {'render_modes': []}

    def __init__(self, simulator: str | None = None, uri: str = 'football_ros://american',
                 control_rate: float = 50.0, sim_step: float = 0.001, timeout: float = 10.0,
                 discovery_timeout: float = 10.0, **options: Any) -> None:
        for name in ('wind_speed', 'wobble_weight'):
            if name in options:
                raise ValueError(f"'{name}' is not an option of SimThrow-v0 (the simulator's)")
        self.task = ThrowTask.from_options(options)
        for name, value, lo, hi in (('control_rate', control_rate, 0.1, 1000.0),
                                    ('sim_step', sim_step, 1e-6, 1.0),
                                    ('timeout', timeout, 0.01, 600.0),
                                    ('discovery_timeout', discovery_timeout, 0.01, 600.0)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
                    lo <= value <= hi):
                raise ValueError(f"'{name}' must be a number in [{lo:g}, {hi:g}], got {value!r}")
        if simulator is not None and not isinstance(simulator, str):
            raise ValueError(f"'simulator' must be a service prefix, got {simulator!r}")
        if not isinstance(uri, str):
            raise ValueError(f"'uri' must be a string, got {uri!r}")
        self.steps_per_control = max(1, round(1.0 / (control_rate * sim_step)))
        self.dt = self.steps_per_control * sim_step
        obs_low, obs_high = self.task.observation_bounds()
        n_state = len(STATE_KEYS) + 1
        self.observation_space = gym.spaces.Box(
            np.concatenate((obs_low, np.full(n_state, -np.inf))),
            np.concatenate((obs_high, np.full(n_state, np.inf))), dtype=np.float64)
        self.action_space = gym.spaces.Box(*self.task.action_bounds(), dtype=np.float64)
        self.hand = (0.0, 0.0, self.task.release_height)
        self._client = SimClient(simulator, float(timeout), float(discovery_timeout))
        try:
            self._pause()
            spawn = SpawnEntity.Request(name=f'simthrow_{os.getpid()}', uri=uri,
                                        allow_renaming=True)
            spawn.initial_pose.pose = _pose(self.hand, (0.0, 0.0, 0.0, 1.0))
            self.entity = self._client.call('spawn_entity', spawn).entity_name
        except BaseException:
            self._client.close()
            raise
        self._target: np.ndarray | None = None
        self._thrown = False
        self._release = np.full(len(ACTION_KEYS), np.nan)
        self._time = 0.0
        self._last: np.ndarray | None = None

    def _pause(self, tries: int = 3) -> None:
        """
        Pause the simulation (already paused is fine).

        Retried after a timeout: a simulator that has just started may serve before its first
        answers reach a client that has just discovered it.
        """
        request = SetSimulationState.Request(
            state=SimulationState(state=SimulationState.STATE_PAUSED))
        for attempt in range(tries):
            try:
                self._client.call('set_simulation_state', request, ok=(
                    Result.RESULT_OK, SetSimulationState.Response.ALREADY_IN_TARGET_STATE))
                return
            except TimeoutError:
                if attempt == tries - 1:
                    raise

    def _read(self) -> np.ndarray:
        request = GetEntityState.Request(entity=self.entity)
        return _state_vector(self._client.call('get_entity_state', request).state)

    def _obs(self, state: np.ndarray) -> np.ndarray:
        return np.concatenate((self._target, state, [self._time]))

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Put the ball at rest at the hand; draw a target (``seed`` reseeds targets, noise)."""
        super().reset(seed=seed)
        target = self.task.sample(self.np_random, 1)[0]
        self._target = target[:5] if self.task.receiver_speed > 0.0 else target[:3]
        rest = EntityState()
        rest.pose = _pose(self.hand, (0.0, 0.0, 0.0, 1.0))
        self._client.call('set_entity_state',
                          SetEntityState.Request(entity=self.entity, state=rest))
        self._thrown, self._time = False, 0.0
        self._last = self._read()
        return self._obs(self._last), {}

    def step(self, action):
        """Throw (first step) and advance one control period; ValueError for a bad action."""
        if self._last is None:
            raise gym.error.ResetNeeded('call reset() first (and after the episode ends)')
        actions = check_actions(action, self.action_space.low, self.action_space.high)
        if not self._thrown:
            self._release = noisy_releases(self.task, actions, self.np_random)[0]
            request = SetEntityState.Request(entity=self.entity,
                                             state=release_message(self.hand, self._release))
            self._client.call('set_entity_state', request)
            self._thrown = True
        info: dict[str, Any] = {'release': self._release.copy()}
        self._client.call('step_simulation', StepSimulation.Request(steps=self.steps_per_control))
        self._time += self.dt
        before, state = self._last, self._read()
        self._last = state
        z = self._target[2]
        reward, terminated = 0.0, False
        if state[2] <= z < before[2]:
            u = (before[2] - z) / (before[2] - state[2])  # the plane's crossing, linear
            t = self._time - (1.0 - u) * self.dt
            ball = before[:2] + u * (state[:2] - before[:2])
            receiver = self._target[3:5] if self._target.size > 3 else np.zeros(2)
            miss = float(np.hypot(*(ball - (self._target[:2] + receiver * t))))
            reward, terminated = -min(miss, self.task.miss_cap), True
            info.update(miss=miss, arrival_time=t)
        truncated = not terminated and self._time >= MAX_TIME
        if truncated:
            reward = -self.task.miss_cap
            info.update(miss=math.inf, arrival_time=math.nan)
        obs = self._obs(state)
        if terminated or truncated:
            self._last = None
        return obs, reward, terminated, truncated, info

    def close(self) -> None:
        """Delete the ball and close the client (idempotent)."""
        client, self._client = getattr(self, '_client', None), None
        if client is None:
            return
        try:
            if client.context.ok():
                client.call('delete_entity', DeleteEntity.Request(entity=self.entity))
        except (RuntimeError, TimeoutError):
            pass  # the simulator is gone or the ball was reset away: nothing to delete
        finally:
            client.close()
