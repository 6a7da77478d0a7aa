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
The simulator's simulation_interfaces services and SimulateSteps action (private names).

A thin adapter: requests are checked here and carried out on the node's
:class:`football_ros.simulation.world.World` under the node's world lock; every request gets
one answer, a refusal with the interface's Result code and a message naming the field. The
simulator node calls :class:`SimulationServices` once; the service names are in qos.py and
msg_docs/simulation_interfaces.md describes them.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
import math
import traceback

from geometry_msgs.msg import Vector3
import numpy as np
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.task import Future
from simulation_interfaces.action import SimulateSteps
from simulation_interfaces.msg import (
    Bounds,
    EntityCategory,
    EntityState,
    Result,
    SimulationState,
    SimulatorFeatures,
    Spawnable,
    SpawnResult,
    TagsFilter,
)
from simulation_interfaces.srv import (
    DeleteEntity,
    GetEntities,
    GetEntitiesStates,
    GetEntityBounds,
    GetEntityInfo,
    GetEntityState,
    GetSimulationState,
    GetSimulatorFeatures,
    GetSpawnables,
    ResetSimulation,
    SetEntityState,
    SetSimulationState,
    SpawnEntities,
    SpawnEntity,
    StepSimulation,
)

from . import messages as mb
from . import qos
from ..physics.presets import PRESETS
from ..physics.release import InitialState
from ..requests import capped, FlightOrder
from ..simulation.world import check_pose, EntityError, MAX_FLIGHT_S, URI_SCHEME

FEATURES = (
    SimulatorFeatures.SPAWNING,
    SimulatorFeatures.SPAWNING_ENTITIES,
    SimulatorFeatures.DELETING,
    SimulatorFeatures.ENTITY_BOUNDS,
    SimulatorFeatures.ENTITY_TAGS,
    SimulatorFeatures.ENTITY_BOUNDS_BOX,
    SimulatorFeatures.ENTITY_CATEGORIES,
    SimulatorFeatures.ENTITY_STATE_GETTING,
    SimulatorFeatures.ENTITY_STATE_SETTING,
    SimulatorFeatures.ENTITY_INFO_GETTING,
    SimulatorFeatures.SPAWNABLES,
    SimulatorFeatures.SIMULATION_RESET,
    SimulatorFeatures.SIMULATION_RESET_TIME,
    SimulatorFeatures.SIMULATION_RESET_STATE,
    SimulatorFeatures.SIMULATION_RESET_SPAWNED,
    SimulatorFeatures.SIMULATION_STATE_GETTING,
    SimulatorFeatures.SIMULATION_STATE_SETTING,
    SimulatorFeatures.SIMULATION_STATE_PAUSE,
    SimulatorFeatures.STEP_SIMULATION_SINGLE,
    SimulatorFeatures.STEP_SIMULATION_MULTIPLE,
    SimulatorFeatures.STEP_SIMULATION_ACTION,
)
"""Exactly what works (GetSimulatorFeatures)."""
MAX_SPAWN_REQUESTS = 1000
"""Most spawn requests of one SpawnEntities call (the largest max_entities)."""
MAX_FEEDBACK = 20
"""Most feedback messages of one SimulateSteps goal (one per chunk of steps)."""
RESET_SCOPES = ResetSimulation.Request.SCOPE_TIME | ResetSimulation.Request.SCOPE_STATE | (
    ResetSimulation.Request.SCOPE_SPAWNED
)
_SPAWN_CODES = {
    'name_invalid': SpawnEntity.Response.NAME_INVALID,
    'name_not_unique': SpawnEntity.Response.NAME_NOT_UNIQUE,
    'no_resource': SpawnEntity.Response.NO_RESOURCE,
    'unsupported_format': SpawnEntity.Response.UNSUPPORTED_FORMAT,
    'not_found': Result.RESULT_NOT_FOUND,
    'pose': SpawnEntity.Response.INVALID_POSE,
}


def result(code: int = Result.RESULT_OK, message: str = '') -> Result:
    """Return a simulation_interfaces/Result (message capped)."""
    return Result(result=code, error_message=capped(message))


class Refusal(Exception):
    """A request refused with ``code`` and ``message``."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


def _finite(values, field: str) -> np.ndarray:
    arr = np.array(values, dtype=float)
    if not np.isfinite(arr).all():
        raise Refusal(
            Result.RESULT_OPERATION_FAILED, f'{field} must be finite, got {arr.tolist()}'
        )
    return arr


def _xyz(v) -> list[float]:
    return [v.x, v.y, v.z]


class SimulationServices:
    """Owns the simulation_interfaces services and action of a simulator node."""

    def __init__(self, node) -> None:
        self._node = node
        for srv_type, name, handler in (
            (GetSimulatorFeatures, qos.GET_SIMULATOR_FEATURES, self._features),
            (GetSpawnables, qos.GET_SPAWNABLES, self._spawnables),
            (SpawnEntity, qos.SPAWN_ENTITY, self._spawn),
            (SpawnEntities, qos.SPAWN_ENTITIES, self._spawn_entities),
            (DeleteEntity, qos.DELETE_ENTITY, self._delete),
            (GetEntities, qos.GET_ENTITIES, self._entities),
            (GetEntityInfo, qos.GET_ENTITY_INFO, self._info),
            (GetEntityBounds, qos.GET_ENTITY_BOUNDS, self._bounds),
            (GetEntityState, qos.GET_ENTITY_STATE, self._state),
            (GetEntitiesStates, qos.GET_ENTITIES_STATES, self._states),
            (SetEntityState, qos.SET_ENTITY_STATE, self._set_state),
            (ResetSimulation, qos.RESET_SIMULATION, self._reset),
            (GetSimulationState, qos.GET_SIMULATION_STATE, self._get_simulation_state),
            (SetSimulationState, qos.SET_SIMULATION_STATE, self._set_simulation_state),
            (StepSimulation, qos.STEP_SIMULATION, self._step),
        ):
            node.create_service(srv_type, name, self._answering(handler))
        self._goal_running = False  # one SimulateSteps goal at a time (executor thread)
        self._stepper = ThreadPoolExecutor(1, thread_name_prefix='simulate-steps')
        self._action = ActionServer(
            node,
            SimulateSteps,
            qos.SIMULATE_STEPS,
            execute_callback=self._simulate_steps,
            goal_callback=self._accept_goal,
            cancel_callback=lambda _goal: CancelResponse.ACCEPT,
        )

    def _answering(self, handler):
        """Wrap a handler: a Refusal or any error becomes the response's Result, once."""

        def serve(request, response):
            try:
                handler(request, response)
                if not hasattr(response, 'result'):
                    return response
                if not response.result.result:
                    response.result = result()  # handlers leave OK implicit
            except Refusal as refusal:
                response.result = result(refusal.code, str(refusal))
            except Exception as exc:  # never let one request take the simulator down
                self._node.get_logger().error(
                    f'{handler.__name__}: internal error\n{traceback.format_exc()}'
                )
                if hasattr(response, 'result'):
                    response.result = result(
                        Result.RESULT_OPERATION_FAILED, f'internal error ({type(exc).__name__})'
                    )
            return response

        return serve

    # --- entities ---------------------------------------------------------------------------
    def _features(self, _request, response) -> None:
        response.features.features = list(FEATURES)
        response.features.spawn_formats = ['football_ros']
        response.features.custom_info = (
            'football_ros simulator: balls as entities, uris '
            + ', '.join(URI_SCHEME + b for b in PRESETS)
            + '; SetEntityState throws (pose and twist in field; body x = spin axis); '
            'see msg_docs/simulation_interfaces.md'
        )

    def _spawnables(self, request, response) -> None:
        for name, preset in PRESETS.items():
            bounds = Bounds(
                type=Bounds.TYPE_SPHERE, points=[Vector3(), Vector3(x=0.5 * preset.length)]
            )
            response.spawnables.append(
                Spawnable(
                    uri=URI_SCHEME + name,
                    description=(
                        f'{name} ball: length {preset.length:g} m, diameter '
                        f'{preset.diameter:g} m, mass {preset.mass:g} kg'
                    ),
                    spawn_bounds=bounds,
                )
            )
        if request.sources:
            response.result = result(
                Result.RESULT_OK, f'sources not searched (built-in presets only): '
                f'{", ".join(str(s)[:64] for s in request.sources[:8])}'
            )

    def _check_frame(self, frame_id: str, code: int) -> None:
        node = self._node
        if frame_id not in ('', node.frame_id):
            raise Refusal(
                code,
                f"header.frame_id '{capped(frame_id, 64)}' is not the world frame "
                f"'{node.frame_id}' (or empty)",
            )

    def _spawn(self, request, response) -> None:
        response.entity_name = self._spawn_one(
            request.name,
            request.allow_renaming,
            request.uri,
            request.resource_string,
            request.entity_namespace,
            request.initial_pose,
        )

    def _spawn_entities(self, request, response) -> None:
        """SpawnEntities: each request as SpawnEntity, one SpawnResult each, in order."""
        spawns = request.spawn_requests
        if len(spawns) > MAX_SPAWN_REQUESTS:
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                f'spawn_requests has {len(spawns)} entries, more than the '
                f'{MAX_SPAWN_REQUESTS} one call may take',
            )
        failed = 0
        for spawn in spawns:
            item = SpawnResult(result=result())
            try:
                item.entity_name = self._spawn_one(
                    spawn.name,
                    spawn.allow_renaming,
                    spawn.entity_resource.uri,
                    spawn.entity_resource.resource_string,
                    spawn.entity_namespace,
                    spawn.initial_pose,
                )
            except Refusal as refusal:
                item.result = result(refusal.code, str(refusal))
                failed += 1
            response.results.append(item)
        if failed:
            response.result = result(
                SpawnEntities.Response.ENTITIES_SPAWN_FAILED,
                f'{failed} of {len(spawns)} spawn requests failed (see results)',
            )

    def _spawn_one(self, name, allow_renaming, uri, resource_string, namespace, pose) -> str:
        """Spawn one ball at rest; return its name (Refusal with SpawnEntity's codes)."""
        node = self._node
        if not uri and resource_string:
            raise Refusal(
                SpawnEntity.Response.UNSUPPORTED_FORMAT,
                'resource_string is not supported: give a uri from GetSpawnables',
            )
        if namespace:
            raise Refusal(
                SpawnEntity.Response.NAMESPACE_INVALID,
                'entity_namespace is not supported (topics are football/<name>/...): leave it '
                'empty',
            )
        self._check_frame(pose.header.frame_id, SpawnEntity.Response.INVALID_POSE)
        q = pose.pose.orientation
        with node._world_lock:
            try:
                with node._lock:
                    entity = node._world.spawn(
                        name, uri, _xyz(pose.pose.position), [q.x, q.y, q.z, q.w], allow_renaming
                    )
            except EntityError as exc:
                raise Refusal(
                    _SPAWN_CODES.get(exc.reason, Result.RESULT_OPERATION_FAILED), str(exc)
                ) from None
            node.add_entity_publishers(entity)
        node.get_logger().info(
            f"spawned '{entity.name}' ({entity.uri})", throttle_duration_sec=0.1
        )
        return entity.name

    def _delete(self, request, response) -> None:
        node = self._node
        with node._world_lock:
            try:
                with node._lock:
                    entity = node._world.delete(request.entity)
            except EntityError as exc:
                code = Result.RESULT_NOT_FOUND if exc.reason == 'not_found' else (
                    Result.RESULT_OPERATION_FAILED
                )
                raise Refusal(code, str(exc)) from None
            node.remove_entity_publishers(entity)

    def _get(self, name: str):
        try:
            return self._node._world.get(name)
        except EntityError as exc:
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None

    def _select(self, filters) -> list:
        """Return the entities passing an EntityFilters (Refusal: what is not supported)."""
        categories = [c.category for c in filters.categories]
        if categories and EntityCategory.CATEGORY_DYNAMIC_OBJECT not in categories:
            return []
        tags = tuple(filters.tags.tags)
        mode = filters.tags.filter_mode
        if mode not in (TagsFilter.FILTER_MODE_ANY, TagsFilter.FILTER_MODE_ALL):
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                f'tags.filter_mode must be 0 (any) or 1 (all), got {filters.tags.filter_mode}',
            )
        sphere = box = None
        bounds = filters.bounds
        points = [_finite(_xyz(p), 'bounds.points') for p in bounds.points]
        if bounds.type == Bounds.TYPE_SPHERE:
            if len(points) != 2 or points[1][0] < 0.0:
                raise Refusal(
                    Result.RESULT_OPERATION_FAILED,
                    'sphere bounds need 2 points: the centre and (radius >= 0, 0, 0)',
                )
            sphere = (points[0], float(points[1][0]))
        elif bounds.type == Bounds.TYPE_BOX:
            if len(points) != 2:
                raise Refusal(Result.RESULT_OPERATION_FAILED, 'box bounds need 2 corner points')
            box = (points[0], points[1])
        elif bounds.type == Bounds.TYPE_CONVEX_HULL:
            raise Refusal(
                Result.RESULT_FEATURE_UNSUPPORTED, 'convex hull bounds are not supported'
            )
        elif bounds.type != Bounds.TYPE_EMPTY:
            raise Refusal(Result.RESULT_OPERATION_FAILED, f'unknown bounds type {bounds.type}')
        try:
            return self._node._world.select(
                filters.filter,
                tags,
                filters.tags.filter_mode == TagsFilter.FILTER_MODE_ALL,
                sphere,
                box,
            )
        except EntityError as exc:
            raise Refusal(Result.RESULT_OPERATION_FAILED, str(exc)) from None

    def _entities(self, request, response) -> None:
        with self._node._lock:
            response.entities = [e.name for e in self._select(request.filters)]

    def _info(self, request, response) -> None:
        with self._node._lock:
            entity = self._get(request.entity)
            response.info.category.category = EntityCategory.CATEGORY_DYNAMIC_OBJECT
            response.info.description = (
                f'{entity.ball_name} ball ({entity.uri}), {entity.condition}'
            )
            response.info.tags = self._node._world.tags(entity)

    def _bounds(self, request, response) -> None:
        """GetEntityBounds: the ball's axis-aligned box in its body frame (x = long axis)."""
        with self._node._lock:
            entity = self._get(request.entity)
        preset = PRESETS[entity.ball_name]
        half_length, radius = 0.5 * preset.length, 0.5 * preset.diameter
        response.bounds = Bounds(
            type=Bounds.TYPE_BOX,
            points=[
                Vector3(x=-half_length, y=-radius, z=-radius),
                Vector3(x=half_length, y=radius, z=radius),
            ],
        )

    def entity_state(self, entity) -> EntityState:
        """Return an entity's EntityState now: pose and twist in the world frame (lock held)."""
        node = self._node
        position, orientation, velocity, omega = entity.state()
        msg = EntityState(header=mb.header(node.stamp_now(), node.frame_id))
        msg.pose = mb.pose_of(position, orientation)
        msg.twist = mb.twist_of(velocity, omega)
        return msg

    def _state(self, request, response) -> None:
        with self._node._lock:
            response.state = self.entity_state(self._get(request.entity))

    def _states(self, request, response) -> None:
        with self._node._lock:
            entities = self._select(request.filters)
            response.entities = [e.name for e in entities]
            response.states = [self.entity_state(e) for e in entities]

    def _set_state(self, request, response) -> None:
        node = self._node
        state = request.state
        self._check_frame(state.header.frame_id, SetEntityState.Response.INVALID_POSE)
        pose, twist = state.pose, state.twist
        q = pose.orientation
        position, orientation = _xyz(pose.position), [q.x, q.y, q.z, q.w]
        velocity = _finite(_xyz(twist.linear), 'twist.linear')
        omega = _finite(_xyz(twist.angular), 'twist.angular')
        try:
            position, orientation = check_pose(position, orientation)
        except EntityError as exc:
            raise Refusal(SetEntityState.Response.INVALID_POSE, str(exc)) from None
        with node._world_lock:
            with node._lock:
                entity = self._get(request.entity)
            if not velocity.any() and not omega.any():
                with node._lock:
                    node._world.place(entity, position, orientation)
                    node._ahead = None
                return
            try:
                initial = InitialState.from_rigid_body(position, velocity, orientation, omega)
                order = FlightOrder(
                    entity.name,
                    entity.ball_name,
                    {},
                    'paper' if node.model == 'release' else node.model,
                    'linear',
                    initial,
                )
                flight = order.flight(node.integration_step)
            except (ValueError, ArithmeticError) as exc:
                raise Refusal(
                    Result.RESULT_OPERATION_FAILED,
                    f"entity '{entity.name}' cannot fly this state: {capped(str(exc))}",
                ) from None
            node.throw_entity(entity, order, flight)

    # --- simulation ------------------------------------------------------------------------
    def _reset(self, request, response) -> None:
        scope = request.scope
        if scope in (ResetSimulation.Request.SCOPE_DEFAULT, ResetSimulation.Request.SCOPE_ALL):
            scope = RESET_SCOPES
        if scope & ~RESET_SCOPES:
            raise Refusal(
                Result.RESULT_FEATURE_UNSUPPORTED,
                f'scope {scope}: only SCOPE_TIME (1), SCOPE_STATE (2), SCOPE_SPAWNED (4), their '
                'sums, SCOPE_DEFAULT and SCOPE_ALL are supported',
            )
        self._node.reset_world(
            clock=bool(scope & ResetSimulation.Request.SCOPE_TIME),
            state=bool(scope & ResetSimulation.Request.SCOPE_STATE),
            spawned=bool(scope & ResetSimulation.Request.SCOPE_SPAWNED),
        )

    def _get_simulation_state(self, _request, response) -> None:
        response.state.state = self._node.simulation_state()

    def _set_simulation_state(self, request, response) -> None:
        node = self._node
        target = request.state.state
        if target not in (
            SimulationState.STATE_PLAYING,
            SimulationState.STATE_PAUSED,
            SimulationState.STATE_STOPPED,
        ):
            code = (
                Result.RESULT_FEATURE_UNSUPPORTED
                if target
                in (
                    SimulationState.STATE_QUITTING,
                    SimulationState.STATE_NO_WORLD,
                    SimulationState.STATE_LOADING_WORLD,
                )
                else Result.RESULT_OPERATION_FAILED
            )
            raise Refusal(code, f'state {target}: only STOPPED (0), PLAYING (1), PAUSED (2)')
        if target == node.simulation_state():
            raise Refusal(
                SetSimulationState.Response.ALREADY_IN_TARGET_STATE,
                f'the simulation is already in state {target}',
            )
        node.set_simulation_state(target)

    def max_steps(self) -> int:
        """Most steps of one StepSimulation or SimulateSteps (MAX_FLIGHT_S of flight)."""
        return int(math.ceil(MAX_FLIGHT_S / self._node.integration_step))

    def _check_steps(self, steps: int) -> None:
        if self._node.simulation_state() == SimulationState.STATE_PLAYING:
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                'the simulation is playing: pause it first (SetSimulationState PAUSED)',
            )
        if steps > self.max_steps():
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                f'steps = {steps} is more than the {self.max_steps()} steps '
                f'({MAX_FLIGHT_S:g} s, after which every flight has ended) one call may take',
            )

    def _step(self, request, response) -> None:
        self._check_steps(int(request.steps))
        self._node.step_world(int(request.steps))

    def _accept_goal(self, _goal) -> GoalResponse:
        """Accept a SimulateSteps goal unless one is running (its steps are checked later)."""
        if self._goal_running:
            self._node.get_logger().warning(
                'simulate_steps: goal rejected, another goal is running', throttle_duration_sec=1.0
            )
            return GoalResponse.REJECT
        self._goal_running = True
        return GoalResponse.ACCEPT

    async def _simulate_steps(self, goal_handle):
        """
        Step ``steps`` in chunks (at most MAX_FEEDBACK, one feedback each), cancelable.

        The chunks run on the stepping thread, so that the executor serves cancel requests (and
        every other request) meanwhile; a cancel or a change to PLAYING stops the run at the
        next chunk boundary (a step boundary), the states after the steps done are published
        and the result says how many ran. The states are published once, at the end.
        """
        try:
            return await self._run_goal(goal_handle)
        finally:
            self._goal_running = False

    async def _run_goal(self, goal_handle):
        node = self._node
        steps = int(goal_handle.request.steps)
        out = SimulateSteps.Result()
        try:
            self._check_steps(steps)
        except Refusal as refusal:
            out.result = result(refusal.code, str(refusal))
            goal_handle.abort()
            return out
        try:
            done, stop = await self._in_worker(self._run_steps, goal_handle, steps)
        except Exception as exc:
            node.get_logger().error(f'simulate_steps: {traceback.format_exc()}')
            out.result = result(
                Result.RESULT_OPERATION_FAILED, f'internal error ({type(exc).__name__})'
            )
            goal_handle.abort()
            return out
        if stop == 'canceled':
            out.result = result(
                Result.RESULT_OPERATION_FAILED, f'canceled after {done} of {steps} steps'
            )
            goal_handle.canceled()
        elif stop == 'playing':
            out.result = result(
                Result.RESULT_OPERATION_FAILED,
                f'the simulation was set playing after {done} of {steps} steps: stopped',
            )
            goal_handle.abort()
        else:
            out.result = result()
            goal_handle.succeed()
        return out

    def _run_steps(self, goal_handle, steps: int) -> tuple[int, str | None]:
        """
        Step a goal's chunks (stepping thread); return the steps done and why it stopped early.

        Feedback after each chunk (rclpy's goal handle publishes from any thread); the states
        after the last chunk are published once.
        """
        node = self._node
        chunk = max(1, -(-steps // MAX_FEEDBACK))
        done, stop, publish = 0, None, None
        try:
            while done < steps:
                if goal_handle.is_cancel_requested:
                    stop = 'canceled'
                    break
                if node.simulation_state() == SimulationState.STATE_PLAYING:
                    stop = 'playing'
                    break
                n = min(chunk, steps - done)
                publish = node.step_world(n, False)
                done += n
                goal_handle.publish_feedback(
                    SimulateSteps.Feedback(completed_steps=done, remaining_steps=steps - done)
                )
        finally:
            if publish is not None:
                publish()  # the states after the last chunk, once
        return done, stop

    def _in_worker(self, fn, *args) -> Future:
        """Run ``fn(*args)`` on the stepping thread; an rclpy Future the executor wakes on."""
        executor = self._node.executor
        future = Future(executor=executor)

        def finished(job) -> None:
            error = job.exception()
            if error is not None:
                future.set_exception(error)
            else:
                future.set_result(job.result())
            if executor is not None:
                executor.wake()  # the awaiting goal resumes now, not at the next other event

        self._stepper.submit(fn, *args).add_done_callback(finished)
        return future

    def close(self) -> None:
        """Stop the stepping thread (a running chunk ends first)."""
        self._stepper.shutdown(wait=True, cancel_futures=True)
