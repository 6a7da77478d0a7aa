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
Where each module's tests are: every module of football_ros -> the test files that test it.

Find a module's tests here (its first file is the main one). The test below fails on a module
without an entry, on an entry for a module that is gone, and on a test file that does not exist:
a new module needs its line (and its tests) here.
"""

from pathlib import Path

TESTS = Path(__file__).resolve().parent
PACKAGE = TESTS.parent / 'football_ros'

MODULE_TESTS: dict[str, tuple[str, ...]] = {
    'football_ros.envs': ('test_envs.py',),
    'football_ros.envs.sim_throw': ('test_sim_throw.py',),
    'football_ros.envs.throw_env': ('test_envs.py',),
    'football_ros.envs.throws': ('test_envs.py',),
    'football_ros.estimation.camera': ('test_camera.py',),
    'football_ros.estimation.camera_fusion': ('test_camera.py', 'test_camera_nodes.py'),
    'football_ros.estimation.detections': ('test_camera.py',),
    'football_ros.estimation.measurement': ('test_tracker_field.py',),
    'football_ros.estimation.rig': ('test_camera.py',),
    'football_ros.estimation.static_frames': ('test_tracker_field.py',),
    'football_ros.identification': ('test_fit.py',),
    'football_ros.identification.coefficients': ('test_fit.py',),
    'football_ros.identification.fit': ('test_fit.py',),
    'football_ros.identification.kernels': ('test_fit.py',),
    'football_ros.identification.problem': ('test_fit.py',),
    'football_ros.identification.solver': ('test_fit.py',),
    'football_ros.identification.track': ('test_fit.py',),
    'football_ros.identification.uncertainty': ('test_fit.py',),
    'football_ros.nodes.cameras': ('test_camera_nodes.py',),
    'football_ros.nodes.logs': ('test_logs.py',),
    'football_ros.nodes.inbox': ('test_release_node.py',),
    'football_ros.nodes.view': ('test_view_node.py',),
    'football_ros.playback': ('test_scene.py',),
    'football_ros.scene': ('test_scene.py',),
    'football_ros.tools.fit': ('test_fit.py',),
    'football_ros.tools.tracks': ('test_fit.py',),
    'football_ros': ('test_cli.py', 'test_architecture.py'),  # numba's cache folder
    'football_ros._early_signals': ('test_runner.py',),
    'football_ros.bagfile': ('test_recorder.py',),
    'football_ros.cli': ('test_cli.py', 'test_physics.py', 'test_montecarlo.py'),
    'football_ros.command_line': ('test_cli.py', 'test_planner_cli.py'),
    'football_ros.programs': ('test_colcon.py', 'test_cli.py', 'test_architecture.py'),
    'football_ros.requests': ('test_requests.py', 'test_release_node.py'),
    'football_ros.strict_yaml': ('test_requests.py',),
    # layer 2: physics
    'football_ros.physics': ('test_physics.py',),
    'football_ros.physics.aero': ('test_full_model.py', 'test_paper.py'),
    'football_ros.physics.batch': ('test_batch.py',),
    'football_ros.physics.dop853': ('test_batch.py',),
    'football_ros.physics.dynamics': ('test_physics.py', 'test_full_model.py'),
    'football_ros.physics.flight': ('test_physics.py', 'test_full_model.py'),
    'football_ros.physics.frames': ('test_physics.py', 'test_release_state.py'),
    'football_ros.physics.step_stability': ('test_step_stability.py',),
    'football_ros.physics.linear_theory': ('test_linear_scalar.py', 'test_physics.py'),
    'football_ros.physics.model_params': ('test_linear_scalar.py', 'test_physics.py'),
    'football_ros.physics.modes': ('test_physics.py', 'test_full_model.py'),
    'football_ros.physics.precompile': ('test_compile.py', 'test_cli.py'),
    'football_ros.physics.presets': ('test_physics.py', 'test_paper.py'),
    'football_ros.physics.quasi_steady': ('test_physics.py', 'test_full_model.py'),
    'football_ros.physics.release': ('test_release_state.py', 'test_physics.py'),
    # layer 3: estimation, planning, simulation
    'football_ros.estimation': ('test_estimation.py',),
    'football_ros.estimation.bound': ('test_prediction_bound.py',),
    'football_ros.estimation.motion': ('test_estimation.py', 'test_refine.py'),
    'football_ros.estimation.multi': ('test_tracker_robustness.py',),
    'football_ros.estimation.refine': ('test_refine.py',),
    'football_ros.estimation.sensor': ('test_estimation.py', 'test_tracker_robustness.py'),
    'football_ros.estimation.tracker': ('test_estimation.py', 'test_tracker_robustness.py'),
    'football_ros.estimation.unscented': ('test_estimation.py',),
    'football_ros.planning': ('test_planner.py',),
    'football_ros.planning.kernels': ('test_planner.py',),
    'football_ros.planning.planner': ('test_planner.py', 'test_planner_cli.py'),
    'football_ros.planning.request': ('test_planner_node.py',),
    'football_ros.planning.robustness': ('test_planner.py',),
    'football_ros.simulation': ('test_world.py',),
    'football_ros.simulation.core': ('test_simulation_core.py', 'test_simulator_burst.py'),
    'football_ros.simulation.kernel': ('test_world.py',),
    'football_ros.simulation.names': ('test_simulation_core.py', 'test_simulator_burst.py'),
    'football_ros.simulation.world': ('test_world.py', 'test_step_stability.py'),
    # layer 5: nodes
    'football_ros.nodes': ('test_topics.py',),
    'football_ros.nodes.console': ('test_cli.py', 'test_release_node.py'),
    'football_ros.nodes.dds': ('test_dds_profile.py',),
    'football_ros.nodes.messages': ('test_simulator_node.py', 'test_rviz.py', 'test_tf.py'),
    'football_ros.nodes.observation_hook': ('test_tracker_node.py', 'test_recorder.py'),
    'football_ros.nodes.params': ('test_parameters.py',),
    'football_ros.nodes.planner': ('test_planner_node.py',),
    'football_ros.nodes.qos': ('test_topics.py',),
    'football_ros.nodes.quiet': ('test_quiet.py', 'test_view_node.py'),
    'football_ros.nodes.recorder': ('test_recorder.py',),
    'football_ros.nodes.reference': ('test_parameters.py',),
    'football_ros.nodes.release': ('test_release_node.py', 'test_security.py'),
    'football_ros.nodes.runner': ('test_runner.py',),
    'football_ros.nodes.simulation_services': (
        'test_simulation_services.py', 'test_simulation_interfaces.py'),
    'football_ros.nodes.simulator': ('test_simulator_node.py', 'test_sim_time.py'),
    'football_ros.nodes.topics': ('test_topics.py',),
    'football_ros.nodes.tracker': ('test_tracker_node.py',),
    # layer 6: tools
    'football_ros.tools': ('test_cli.py',),
    'football_ros.tools.compile': ('test_compile.py',),
    'football_ros.tools.demo': ('test_demo.py',),
    'football_ros.tools.fastcsv': ('test_montecarlo.py', 'test_cli.py'),
    'football_ros.tools.figures': ('test_physics.py', 'test_recorder.py'),
    'football_ros.tools.flightdata': ('test_flightdata.py', 'test_physics.py'),
    'football_ros.tools.mc_engine': ('test_montecarlo.py', 'test_montecarlo_dask.py'),
    'football_ros.tools.montecarlo': ('test_montecarlo.py', 'test_montecarlo_dask.py'),
    'football_ros.tools.paper': ('test_paper.py',),
    'football_ros.tools.plan': ('test_planner_cli.py',),
}


def _modules() -> set[str]:
    out = set()
    for path in PACKAGE.rglob('*.py'):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix('').parts)
        out.add('.'.join(parts[:-1] if parts[-1] == '__init__' else parts))
    return out


def test_every_module_has_its_tests_listed():
    modules = _modules()
    missing = sorted(modules - set(MODULE_TESTS))
    gone = sorted(set(MODULE_TESTS) - modules)
    assert not missing, f'modules without an entry in MODULE_TESTS: {missing}'
    assert not gone, f'entries for modules that do not exist: {gone}'
    absent = sorted({f for files in MODULE_TESTS.values() for f in files
                     if not (TESTS / f).is_file()})
    assert not absent, f'test files named in MODULE_TESTS that do not exist: {absent}'
    assert all(MODULE_TESTS.values())
