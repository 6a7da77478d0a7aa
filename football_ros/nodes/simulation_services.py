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

A thin adapter: requests are checked here and carried out as operations of the node's
:class:`football_ros.simulation.core.Simulation` (which takes its own lock); every request
gets one answer, a refusal with the interface's Result code and a message naming the field.
Every service and the action keep ``qos.SERVICE_DEPTH`` requests waiting (a burst of callers is
queued, not dropped). The simulator node calls :class:`SimulationServices` once; the service
names are in qos.py (at root names too with ``root_services``) and
msg_docs/simulation_interfaces.md describes them, with the frames they use.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
import math
import time
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
from .logs import throttled
from ..physics.presets import PRESETS
from ..physics.release import InitialState
from ..requests import capped, FlightOrder
from ..simulation.core import PLAYING, STOPPED
from ..simulation.world import check_pose, EntityError, MAX_FLIGHT_S, URI_SCHEME

WORLD_FRAMES = ('', 'world')
"""Frame ids that name the world frame besides the node's frame_id (the standard's default)."""
CHUNK_SECONDS = 0.02
"""A SimulateSteps goal steps in chunks of about this much CPU [s] (feedback and cancel
between chunks), estimated from the last chunk's cost per ball-step."""

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


def _rotate(q, v) -> np.ndarray:
    """Rotate vector ``v`` by the unit quaternion ``q`` (x, y, z, w)."""
    x, y, z, w = q
    u = np.array([x, y, z])
    v = np.asarray(v, dtype=float)
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def _compose(q1, q2) -> np.ndarray:
    """Quaternion product q1 * q2 (x, y, z, w)."""
    x1, y1, z1, w1 = q1
    x2, y2, z2, w2 = q2
    return np.array([
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
    ])


class SimulationServices:
    """Owns the simulation_interfaces services and action of a simulator node."""

    def __init__(self, node, root_names: bool = False) -> None:
        self._node = node
        self._sim = node.sim
        depth = qos.service_qos()
        prefixes = ('',) + (('/',) if root_names else ())
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
            for prefix in prefixes:
                full = name if not prefix else prefix + name.rsplit('/', 1)[-1]
                node.create_service(srv_type, full, self._answering(handler), qos_profile=depth)
        self._goal_running = False  # one SimulateSteps goal at a time (executor thread)
        self._stepper = ThreadPoolExecutor(1, thread_name_prefix='simulate-steps')
        self._step_cost = 1e-6  # CPU seconds per ball-step of the last chunk (chunk sizing)
        self._actions = [
            ActionServer(
                node,
                SimulateSteps,
                name if not prefix else prefix + name.rsplit('/', 1)[-1],
                execute_callback=self._simulate_steps,
                goal_callback=self._accept_goal,
                cancel_callback=lambda _goal: CancelResponse.ACCEPT,
                goal_service_qos_profile=depth,
                result_service_qos_profile=depth,
                cancel_service_qos_profile=depth,
                result_timeout=node.goal_result_timeout,
            )
            for name in (qos.SIMULATE_STEPS,)
            for prefix in prefixes
        ]

    def _answering(self, handler):
        """
        Wrap a handler: a Refusal or any error becomes the response's Result, once.

        Each but StepSimulation's lets a tick due now go first (:class:`.simulator.TickGate`).
        """
        gate = self._node.tick_gate if handler != self._step else None

        def serve(request, response):
            if gate is not None:
                gate.wait_clear()
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
            + f"; world frame '{self._node.frame_id}' (also named 'world' or ''); "
            'SetEntityState throws (pose and twist in the header frame: the world or an '
            'entity; body x = the long axis); see msg_docs/simulation_interfaces.md'
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

    def _reference(self, frame_id: str, code: int):
        """
        Return the reference of a header frame: None for the world, else the entity's state.

        The world: '', 'world' or the node's frame_id; an entity: its name or its TF frame
        (child_frame_id/name). Refusal(code) for any other frame.
        """
        node = self._node
        if frame_id in WORLD_FRAMES or frame_id == node.frame_id:
            return None
        name = frame_id
        prefix = node.child_frame_id + '/'
        if frame_id.startswith(prefix):
            name = frame_id[len(prefix):]
        try:
            return self._sim.entity_state(name)
        except EntityError:
            raise Refusal(
                code,
                f"header.frame_id '{capped(frame_id, 64)}' is neither the world frame "
                f"('{node.frame_id}', 'world' or empty) nor an entity's frame",
            ) from None

    def _in_world(self, header, pose, code: int) -> tuple[list, list, object]:
        """Return a pose in a header's frame as (position, orientation) in the world, reference."""
        ref = self._reference(header.frame_id, code)
        q = pose.orientation
        position, orientation = _xyz(pose.position), [q.x, q.y, q.z, q.w]
        if ref is None:
            return position, orientation, None
        position = _finite(position, 'pose.position')
        orientation = _finite(orientation, 'pose.orientation')
        world_position = ref.position + _rotate(ref.orientation, position)
        return world_position.tolist(), _compose(ref.orientation, orientation).tolist(), ref

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
                Result.RESULT_FEATURE_UNSUPPORTED,
                'entity_namespace is not supported (topics are football/<name>/...): leave it '
                'empty',
            )
        position, orientation, _ref = self._in_world(
            pose.header, pose.pose, SpawnEntity.Response.INVALID_POSE
        )
        with self._sim.lock:  # spawned and its publishers made before any tick shows it
            try:
                entity = self._sim.spawn(name, uri, position, orientation, allow_renaming)
            except EntityError as exc:
                raise Refusal(
                    _SPAWN_CODES.get(exc.reason, Result.RESULT_OPERATION_FAILED), str(exc)
                ) from None
            node.add_entity_publishers(entity)
        throttled(
            node.get_logger(), 'info',
            f"spawned '{entity.name}' ({entity.uri})",
            0.1,
        )
        return entity.name

    def _delete(self, request, response) -> None:
        try:
            entity = self._sim.delete(request.entity)
        except EntityError as exc:
            code = Result.RESULT_NOT_FOUND if exc.reason == 'not_found' else (
                Result.RESULT_OPERATION_FAILED
            )
            raise Refusal(code, str(exc)) from None
        self._node.remove_entity_publishers([entity])

    def _filters(self, filters) -> dict:
        """Return an EntityFilters as Simulation.select's arguments (Refusal: unsupported)."""
        categories = [c.category for c in filters.categories]
        if categories and EntityCategory.CATEGORY_DYNAMIC_OBJECT not in categories:
            return None
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
        return {
            'pattern': filters.filter,
            'tags': tuple(filters.tags.tags),
            'all_tags': mode == TagsFilter.FILTER_MODE_ALL,
            'sphere': sphere,
            'box': box,
        }

    def _select(self, filters, states: bool) -> list:
        arguments = self._filters(filters)
        if arguments is None:
            return []
        try:
            return self._sim.select(**arguments, states=states)
        except EntityError as exc:
            raise Refusal(Result.RESULT_OPERATION_FAILED, str(exc)) from None

    def _entities(self, request, response) -> None:
        response.entities = self._select(request.filters, states=False)

    def _info(self, request, response) -> None:
        try:
            uri, condition, tags = self._sim.describe(request.entity)
        except EntityError as exc:
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None
        response.info.category.category = EntityCategory.CATEGORY_DYNAMIC_OBJECT
        response.info.description = f'{uri[len(URI_SCHEME):]} ball ({uri}), {condition}'
        response.info.tags = tags

    def _bounds(self, request, response) -> None:
        """GetEntityBounds: the ball's axis-aligned box in its body frame (x = long axis)."""
        try:
            preset = PRESETS[self._sim.ball_of(request.entity)]
        except EntityError as exc:
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None
        half_length, radius = 0.5 * preset.length, 0.5 * preset.diameter
        response.bounds = Bounds(
            type=Bounds.TYPE_BOX,
            points=[
                Vector3(x=-half_length, y=-radius, z=-radius),
                Vector3(x=half_length, y=radius, z=radius),
            ],
        )

    def entity_state(self, values) -> EntityState:
        """
        Return the EntityState of EntityValues: pose, twist and acceleration in the world.

        header.frame_id is the world frame; the twist and acceleration are observed in it
        and expressed in its axes (as Gazebo reads them), not in the body frame.
        """
        node = self._node
        msg = EntityState(header=mb.header(node.stamp_now(), node.frame_id))
        msg.pose = mb.pose_of(values.position, values.orientation)
        msg.twist = mb.twist_of(values.velocity, values.angular_velocity)
        msg.acceleration.linear = mb.vector3(values.acceleration)
        return msg

    def _state(self, request, response) -> None:
        try:
            values = self._sim.entity_state(request.entity)
        except EntityError as exc:
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None
        response.state = self.entity_state(values)

    def _states(self, request, response) -> None:
        values = self._select(request.filters, states=True)
        response.entities = [v.name for v in values]
        response.states = [self.entity_state(v) for v in values]

    def _set_state(self, request, response) -> None:
        node = self._node
        state = request.state
        position, orientation, ref = self._in_world(
            state.header, state.pose, SetEntityState.Response.INVALID_POSE
        )
        velocity = _finite(_xyz(state.twist.linear), 'twist.linear')
        omega = _finite(_xyz(state.twist.angular), 'twist.angular')
        if ref is not None:  # observed in the entity's frame: its axes and its motion
            velocity = ref.velocity + _rotate(ref.orientation, velocity)
            omega = ref.angular_velocity + _rotate(ref.orientation, omega)
        try:
            position, orientation = check_pose(position, orientation)
        except EntityError as exc:
            raise Refusal(SetEntityState.Response.INVALID_POSE, str(exc)) from None
        try:
            ball = self._sim.ball_of(request.entity)
        except EntityError as exc:
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None
        if not velocity.any() and not omega.any():
            self._sim.place(request.entity, position, orientation)
            return
        try:
            initial = InitialState.from_rigid_body(position, velocity, orientation, omega)
            order = FlightOrder(
                request.entity,
                ball,
                {},
                'paper' if node.model == 'release' else node.model,
                'linear',
                initial,
            )
            flight = order.flight(node.integration_step)
        except (ValueError, ArithmeticError) as exc:
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                f"entity '{request.entity}' cannot fly this state: {capped(str(exc))}",
            ) from None
        try:
            node.throw_entity(request.entity, order, flight)
        except EntityError as exc:  # deleted meanwhile
            raise Refusal(Result.RESULT_NOT_FOUND, str(exc)) from None

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
        response.state.state = self._sim.state

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
        if target == self._sim.state:
            raise Refusal(
                SetSimulationState.Response.ALREADY_IN_TARGET_STATE,
                f'the simulation is already in state {target}',
            )
        node.set_simulation_state(target)

    def max_steps(self) -> int:
        """Most steps of one StepSimulation or SimulateSteps (MAX_FLIGHT_S of flight)."""
        return int(math.ceil(MAX_FLIGHT_S / self._node.integration_step))

    def _check_steps(self, steps: int) -> None:
        state = self._sim.state
        if state == PLAYING:
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                'the simulation is playing: pause it first (SetSimulationState PAUSED)',
            )
        if state == STOPPED:
            raise Refusal(
                Result.RESULT_OPERATION_FAILED,
                'the simulation is stopped: pause it first (SetSimulationState PAUSED)',
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
            throttled(
                self._node.get_logger(), 'warning',
                'simulate_steps: goal rejected, another goal is running',
                1.0,
            )
            return GoalResponse.REJECT
        self._goal_running = True
        return GoalResponse.ACCEPT

    async def _simulate_steps(self, goal_handle):
        """
        Step ``steps`` in chunks of about CHUNK_SECONDS of CPU, one feedback each, cancelable.

        The chunks run on the stepping thread, so that the executor serves cancel requests (and
        every other request) meanwhile; a cancel or a change to PLAYING stops the run at the
        next chunk boundary (a step boundary), the states after the steps done are published
        and the result says how many ran. A goal that fits one chunk is one compiled pass, run
        in the executor's thread (a hand-off would cost more than the chunk).
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
            if steps * max(1, self._sim.flying_count()) * self._step_cost <= CHUNK_SECONDS:
                # One chunk: stepped here, as StepSimulation is (no thread hand-off); cancels
                # wait at most that chunk, as they would on the stepping thread.
                done, stop = self._run_steps(goal_handle, steps)
            else:
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
        Step a goal's chunks (stepping thread; one chunk: the executor's); return steps done, why.

        A chunk is as many steps as fit CHUNK_SECONDS at the last chunk's cost per ball-step;
        feedback after each chunk but the goal's last (rclpy's goal handle publishes from any
        thread), so a run stopped early has told its steps done (a feedback of 0 if it stopped
        before the first chunk) and a finished goal has no feedback its result repeats (a goal
        of one chunk: none). The states are published after each chunk.
        """
        sim = self._sim
        done, stop = 0, None
        while done < steps:
            if goal_handle.is_cancel_requested:
                stop = 'canceled'
                break
            if sim.state == PLAYING:
                stop = 'playing'
                break
            balls = max(1, sim.flying_count())
            n = min(steps - done, max(1, int(CHUNK_SECONDS / (self._step_cost * balls))))
            start = time.thread_time()
            self._node.step_world(n)
            self._step_cost = max(1e-8, (time.thread_time() - start) / (n * balls))
            done += n
            if done < steps:
                goal_handle.publish_feedback(
                    SimulateSteps.Feedback(completed_steps=done, remaining_steps=steps - done)
                )
        if stop is not None and not done:
            goal_handle.publish_feedback(SimulateSteps.Feedback(remaining_steps=steps))
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
