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
A generic simulation_interfaces client: it knows the standard interfaces, not football_ros.

    python generic_sim_client.py SIMULATOR_NODE THROWS_JSON OUT_JSON

Against the simulator node SIMULATOR_NODE (e.g. /football_simulator): reads the features and
the spawnables, pauses, resets, spawns one entity per throw of THROWS_JSON (a list of
{name, uri, position, orientation, velocity, angular_velocity} in the world frame), sets their
states (the throw), steps the simulation in lock-step (StepSimulation and the SimulateSteps
action), reads every state after each call, resets, and plays the same again. Writes the
states read ({"runs": [[{"steps": n, "states": {name: [x, y, z, qx, qy, qz, qw, vx, vy, vz,
wx, wy, wz]}}, ...], ...], "features": [...], ...}) to OUT_JSON. No football_ros import.
"""

import json
import sys
import time

from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3
import rclpy
from rclpy.action import ActionClient
from simulation_interfaces.action import SimulateSteps
from simulation_interfaces.msg import EntityState, Result, SimulationState
from simulation_interfaces.srv import (
    GetEntitiesStates,
    GetSimulatorFeatures,
    GetSpawnables,
    ResetSimulation,
    SetEntityState,
    SetSimulationState,
    SpawnEntity,
    StepSimulation,
)

SCHEDULE = (1, 99, 400, 500)  # StepSimulation calls, then one SimulateSteps goal
ACTION_STEPS = 700


class Client:
    """Service and action calls to one simulator, each waited for."""

    def __init__(self, node, simulator: str) -> None:
        self.node, self.simulator = node, simulator.rstrip('/')
        self.clients = {}

    def call(self, srv_type, name: str, request, timeout: float = 30.0):
        client = self.clients.get(name)
        if client is None:
            client = self.clients[name] = self.node.create_client(
                srv_type, f'{self.simulator}/{name}'
            )
            if not client.wait_for_service(timeout_sec=timeout):
                raise SystemExit(f'no service {self.simulator}/{name}')
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self.node, future, timeout_sec=timeout)
        if not future.done():
            raise SystemExit(f'{name}: no answer in {timeout} s')
        return future.result()

    def ok(self, srv_type, name: str, request):
        response = self.call(srv_type, name, request)
        if response.result.result != Result.RESULT_OK:
            raise SystemExit(f'{name} refused: {response.result.error_message}')
        return response

    def simulate_steps(self, steps: int) -> tuple[int, list[int]]:
        client = ActionClient(self.node, SimulateSteps, f'{self.simulator}/simulate_steps')
        if not client.wait_for_server(timeout_sec=30.0):
            raise SystemExit('no simulate_steps action')
        feedback = []
        goal = client.send_goal_async(
            SimulateSteps.Goal(steps=steps),
            feedback_callback=lambda msg: feedback.append(int(msg.feedback.completed_steps)),
        )
        rclpy.spin_until_future_complete(self.node, goal, timeout_sec=30.0)
        handle = goal.result()
        if not handle.accepted:
            raise SystemExit('simulate_steps goal rejected')
        done = handle.get_result_async()
        rclpy.spin_until_future_complete(self.node, done, timeout_sec=60.0)
        result = done.result().result.result
        if result.result != Result.RESULT_OK:
            raise SystemExit(f'simulate_steps refused: {result.error_message}')
        client.destroy()
        return steps, feedback


def state_list(state: EntityState) -> list[float]:
    p, q = state.pose.position, state.pose.orientation
    v, w = state.twist.linear, state.twist.angular
    return [p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z]


def play(client: Client, throws: list[dict]) -> list[dict]:
    reset = ResetSimulation.Request(scope=ResetSimulation.Request.SCOPE_ALL)
    client.ok(ResetSimulation, 'reset_simulation', reset)
    for throw in throws:
        spawn = SpawnEntity.Request(name=throw['name'], uri=throw['uri'])
        spawn.initial_pose.pose = Pose(
            position=Point(**dict(zip('xyz', throw['position']))),
            orientation=Quaternion(**dict(zip('xyzw', throw['orientation']))),
        )
        name = client.ok(SpawnEntity, 'spawn_entity', spawn).entity_name
        assert name == throw['name'], name
        state = EntityState()
        state.header.frame_id = ''  # empty: the world frame
        state.pose = spawn.initial_pose.pose
        state.twist = Twist(
            linear=Vector3(**dict(zip('xyz', throw['velocity']))),
            angular=Vector3(**dict(zip('xyz', throw['angular_velocity']))),
        )
        request = SetEntityState.Request(entity=name, state=state)
        client.ok(SetEntityState, 'set_entity_state', request)
    readings, total = [], 0
    calls = [('service', n) for n in SCHEDULE] + [('action', ACTION_STEPS)]
    for how, n in calls:
        if how == 'service':
            client.ok(StepSimulation, 'step_simulation', StepSimulation.Request(steps=n))
        else:
            client.simulate_steps(n)
        total += n
        states = client.ok(GetEntitiesStates, 'get_entities_states', GetEntitiesStates.Request())
        readings.append(
            {
                'steps': total,
                'states': {
                    name: state_list(s)
                    for name, s in zip(states.entities, states.states)
                    if name in {t['name'] for t in throws}
                },
            }
        )
    return readings


def main(argv: list[str]) -> int:
    simulator, throws_path, out_path = argv[1:4]
    throws = json.loads(open(throws_path).read())
    rclpy.init()
    node = rclpy.create_node('generic_sim_client')
    client = Client(node, simulator)
    features = client.call(
        GetSimulatorFeatures, 'get_simulator_features', GetSimulatorFeatures.Request()
    )
    spawnables = client.ok(GetSpawnables, 'get_spawnables', GetSpawnables.Request())
    pause = SetSimulationState.Request(state=SimulationState(state=SimulationState.STATE_PAUSED))
    paused = client.call(SetSimulationState, 'set_simulation_state', pause)
    started = time.monotonic()
    runs = [play(client, throws), play(client, throws)]
    out = {
        'features': list(features.features.features),
        'spawnables': [s.uri for s in spawnables.spawnables],
        'pause_result': paused.result.result,
        'runs': runs,
        'seconds': time.monotonic() - started,
    }
    with open(out_path, 'w') as handle:
        json.dump(out, handle)
    node.destroy_node()
    rclpy.shutdown()
    return 0


if __name__ == '__main__':
    raise SystemExit(main(sys.argv))
