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
The launch file against the params YAML and the nodes' declared parameters.

``launch`` / ``launch_ros`` are not on PyPI: the launch file is loaded with small stand-ins for
their classes that only record what they are given, then its description is walked like
``ros2 launch`` would (arguments, group, OpaqueFunction) to get every node and its parameters.
What the nodes declare is read from running nodes with the rcl_interfaces parameter services.
"""

import importlib.util
import math
from pathlib import Path
import re
import sys
import types

from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import pytest
from rcl_interfaces.srv import GetParameters, ListParameters
from rosutil import call
import yaml

REPO = Path(__file__).resolve().parents[1]
LAUNCH_FILE = REPO / 'launch' / 'football.launch.py'
INSTALLED = {'football_ros', 'rviz2'}  # what the stand-in ament index finds
CONFIG = REPO / 'config' / 'football.yaml'


class _Recorded:

    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class LaunchConfiguration(_Recorded):

    def perform(self, context):
        return context.launch_configurations[self.args[0]]


class ParameterValue(_Recorded):

    def resolve(self, context):
        text = self.args[0].perform(context)
        kind = self.kwargs['value_type']
        return yaml.safe_load(text) if kind is bool else kind(text)


def _stub_modules(monkeypatch):
    names = {
        'launch': ['LaunchDescription'],
        'launch.actions': [
            'DeclareLaunchArgument',
            'GroupAction',
            'LogInfo',
            'OpaqueFunction',
            'Shutdown',
        ],
        'launch.substitutions': [],
        'launch_ros': [],
        'launch_ros.actions': ['Node', 'PushRosNamespace'],
        'launch_ros.parameter_descriptions': [],
    }
    for module_name, classes in names.items():
        module = types.ModuleType(module_name)
        for cls in classes:
            setattr(module, cls, type(cls, (_Recorded,), {}))
        monkeypatch.setitem(sys.modules, module_name, module)
    sys.modules['launch.substitutions'].LaunchConfiguration = LaunchConfiguration
    sys.modules['launch_ros.parameter_descriptions'].ParameterValue = ParameterValue
    ament = types.ModuleType('ament_index_python.packages')

    class PackageNotFoundError(KeyError):
        pass

    def share(package):
        if package not in INSTALLED:
            raise PackageNotFoundError(package)
        return str(REPO)

    ament.PackageNotFoundError = PackageNotFoundError
    ament.get_package_share_directory = share
    monkeypatch.setitem(sys.modules, 'ament_index_python.packages', ament)


def launch(monkeypatch, warnings=None, **arguments):
    """Return (declared arguments, {node name: (node, resolved parameters)}) of ``arguments``."""
    _stub_modules(monkeypatch)
    spec = importlib.util.spec_from_file_location('football_launch', LAUNCH_FILE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    declared, nodes = {}, {}
    context = types.SimpleNamespace(launch_configurations={})

    def resolve(value):
        if isinstance(value, LaunchConfiguration):
            return value.perform(context)
        if isinstance(value, ParameterValue):
            return value.resolve(context)
        if isinstance(value, dict):
            return {k: resolve(v) for k, v in value.items()}
        return value

    def visit(action):
        kind = type(action).__name__
        if kind == 'DeclareLaunchArgument':
            name = action.args[0]
            declared[name] = action.kwargs
            context.launch_configurations[name] = arguments.pop(
                name, action.kwargs['default_value']
            )
        elif kind == 'GroupAction':
            for child in action.args[0]:
                visit(child)
        elif kind == 'OpaqueFunction':
            for child in action.kwargs['function'](context):
                visit(child)
        elif kind == 'PushRosNamespace':
            context.launch_configurations['ros_namespace'] = resolve(action.args[0])
        elif kind == 'Node':
            nodes[action.kwargs['name']] = (
                action,
                [resolve(p) for p in action.kwargs.get('parameters', [])],
            )
        elif kind == 'LogInfo' and warnings is not None:
            warnings.append(action.kwargs['msg'])
        else:
            raise AssertionError(f'unexpected launch action {kind}')

    for action in description.args[0]:
        visit(action)
    assert not arguments, f'not declared by the launch file: {arguments}'
    return declared, nodes


def test_defaults_leave_the_params_file_in_force(monkeypatch):
    declared, nodes = launch(monkeypatch)
    assert set(declared) == {
        'params_file',
        'namespace',
        'publish_rate',
        'use_sim_time',
        'record',
        'tracker',
        'camera_rate',
        'rviz',
        'rviz_config',
        'planner',
        'view',
        'security',
        'keystore',
        'allow_reconfigure',
        'camera_rig',
    }
    assert set(nodes) == {'football_simulator', 'football_release'}
    assert nodes['football_simulator'][1] == [str(CONFIG)]  # no override of the file's values
    assert nodes['football_release'][1] == [str(CONFIG), {'use_sim_time': False}]
    assert Path(declared['rviz_config']['default_value']) == REPO / 'rviz' / 'football.rviz'


@pytest.mark.parametrize('text, value', [('1000', 1000.0), ('500.5', 500.5), (' 20 ', 20.0)])
def test_publish_rate_given_is_a_double(monkeypatch, text, value):
    _, nodes = launch(monkeypatch, publish_rate=text)
    override = nodes['football_simulator'][1][1]
    assert override == {'publish_rate': value} and type(override['publish_rate']) is float


def test_bad_arguments_name_the_argument(monkeypatch):
    for text in ('fast', 'nan', 'inf', '-inf', '1e999'):
        with pytest.raises(ValueError, match="'publish_rate'"):
            launch(monkeypatch, publish_rate=text)
    with pytest.raises(ValueError, match="'use_sim_time'"):
        launch(monkeypatch, use_sim_time='maybe')


def test_sim_time_record_rviz_namespace(monkeypatch):
    _, nodes = launch(
        monkeypatch, use_sim_time='true', record='true', rviz='true', namespace='team1'
    )
    assert set(nodes) == {'football_simulator', 'football_release', 'football_recorder', 'rviz2'}
    assert nodes['football_simulator'][1][1] == {'publish_clock': True}
    for name in ('football_release', 'football_recorder', 'rviz2'):
        assert nodes[name][1][-1] == {'use_sim_time': True}
    rviz = nodes['rviz2'][0]
    assert rviz.kwargs['package'] == 'rviz2'
    assert rviz.kwargs['arguments'] == ['-d', str(REPO / 'rviz' / 'football.rviz')]


def test_rviz_without_rviz2_is_a_warning_and_the_rest_starts(monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], 'INSTALLED', {'football_ros'})
    warnings = []
    _, nodes = launch(monkeypatch, warnings, rviz='true', record='true')
    assert set(nodes) == {'football_simulator', 'football_release', 'football_recorder'}
    assert warnings == ['WARNING: rviz:=true, but rviz2 is not installed: not started']


@pytest.mark.parametrize(
    'arguments, named',
    [
        ({'record': 'maybe'}, "'record'"),
        ({'rviz': 'yes please'}, "'rviz'"),
        ({'tracker': '2'}, "'tracker'"),
        ({'publish_rate': '5000'}, "'publish_rate' must be in [1, 2000]"),
        ({'publish_rate': '0.5'}, "'publish_rate' must be in [1, 2000]"),
        ({'camera_rate': '-1'}, "'camera_rate' must be in [0, 1000]"),
        ({'params_file': '/nonexistent.yaml'}, "'params_file'"),
    ],
)
def test_a_bad_argument_starts_nothing(monkeypatch, arguments, named):
    # The nodes are made by one function that checks every argument first: a bad one raises
    # before any node action exists, so launch starts nothing.
    with pytest.raises(ValueError, match=re.escape(named)):
        launch(monkeypatch, **arguments)


def test_the_core_nodes_end_the_launch_when_one_exits(monkeypatch):
    _, nodes = launch(monkeypatch, record='true', tracker='true')
    for name in ('football_simulator', 'football_release'):
        assert type(nodes[name][0].kwargs['on_exit']).__name__ == 'Shutdown'


def test_tracker_turns_the_camera_on(monkeypatch):
    _, nodes = launch(monkeypatch, tracker='true')
    assert set(nodes) == {'football_simulator', 'football_release', 'football_tracker'}
    assert nodes['football_simulator'][1][1] == {'observation_rate': 60.0}
    _, nodes = launch(monkeypatch, tracker='true', camera_rate='120')
    assert nodes['football_simulator'][1][1] == {'observation_rate': 120.0}
    _, nodes = launch(monkeypatch, camera_rate='30')  # a detector elsewhere; the camera alone
    assert set(nodes) == {'football_simulator', 'football_release'}
    assert nodes['football_simulator'][1][1] == {'observation_rate': 30.0}
    with pytest.raises(ValueError, match="'camera_rate'"):
        launch(monkeypatch, camera_rate='often')


def test_a_camera_rig_goes_to_the_simulator_and_its_cameras_to_the_tracker(monkeypatch):
    rig = REPO / 'config' / 'rig_sideline.yaml'
    _, nodes = launch(monkeypatch, tracker='true', camera_rig=str(rig))
    assert nodes['football_simulator'][1][1] == {'camera_rig': str(rig)}  # no 3D camera
    assert nodes['football_tracker'][1][1]['cameras'] == ['sideline_near', 'sideline_far']
    _, nodes = launch(monkeypatch, camera_rig=str(rig), camera_rate='30')
    assert nodes['football_simulator'][1][1] == {'camera_rig': str(rig), 'observation_rate': 30.0}
    with pytest.raises(ValueError, match="'camera_rig': .*cannot read"):
        launch(monkeypatch, camera_rig='/nonexistent/rig.yaml')
    with pytest.raises(ValueError, match="'camera_rig': .*football.yaml: a rig is a mapping"):
        launch(monkeypatch, camera_rig=str(REPO / 'config' / 'football.yaml'))


def test_every_launched_node_has_a_section_in_the_yaml(monkeypatch):
    _, nodes = launch(monkeypatch, record='true', tracker='true', planner='true', view='true')
    assert nodes['football_view'][0].kwargs['executable'] == 'view'
    sections = yaml.safe_load(CONFIG.read_text())
    for name, (node, _params) in nodes.items():
        assert node.kwargs['package'] == 'football_ros'
        assert f'/**/{name}' in sections, name
    assert set(sections) == {f'/**/{name}' for name in nodes}


def _section(name):
    return yaml.safe_load(CONFIG.read_text())[f'/**/{name}']['ros__parameters']


@pytest.mark.parametrize(
    'command, node_name', [('simulator', 'football_simulator'), ('release', 'football_release')]
)
def test_yaml_keys_are_declared_and_applied_in_a_namespace(
    start_node, collector, tmp_path, command, node_name
):
    """
    Every key of the node's YAML section is a parameter it declares, with the YAML's type.

    And a changed value reaches the node run under -r __ns:=/team1 (wildcard keys).
    """
    section = _section(node_name)
    changed = dict(section, integration_step=0.002)
    params = tmp_path / 'params.yaml'
    params.write_text(yaml.safe_dump({f'/**/{node_name}': {'ros__parameters': changed}}))
    start_node(command, '--ros-args', '-r', '__ns:=/team1', '--params-file', str(params))
    fqn = f'/team1/{node_name}'
    names = call(
        collector, ListParameters, f'{fqn}/list_parameters', ListParameters.Request()
    ).result.names
    assert set(section) <= set(names), set(section) - set(names)
    values = call(
        collector,
        GetParameters,
        f'{fqn}/get_parameters',
        GetParameters.Request(names=list(section)),
    ).values
    got = {}
    for key, value in zip(section, values):
        got[key] = {
            1: value.bool_value,
            2: value.integer_value,
            3: value.double_value,
            4: value.string_value,
        }[value.type]
    assert got == changed
    for key in section:  # the types rcl reads from the YAML are the declared ones
        assert type(got[key]) is type(section[key]), key


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.text(max_size=40))
def test_publish_rate_fuzz_is_a_finite_double_or_a_clear_error(monkeypatch, text):
    try:
        _, nodes = launch(monkeypatch, publish_rate=text)
    except ValueError as exc:
        assert "'publish_rate'" in str(exc) and len(str(exc)) < 200
        return
    params = nodes['football_simulator'][1]
    if text.strip():
        assert math.isfinite(params[1]['publish_rate']) and params[1]['publish_rate'] == float(
            text
        )
    else:
        assert params == [str(CONFIG)]
