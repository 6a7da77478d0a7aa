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

"""The nodes' parameter tables: declarations, --help, descriptors, config file and reference."""

from pathlib import Path

from cli_run import run_cli
from football_ros.nodes.reference import node_tables
from football_ros.programs import NODES
import pytest
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import (
    DescribeParameters,
    GetParameters,
    ListParameters,
    SetParameters,
)
from rosutil import call
import yaml

REPO = Path(__file__).resolve().parents[1]
NODE_NAMES = {
    'simulator': 'football_simulator',
    'release': 'football_release',
    'tracker': 'football_tracker',
    'recorder': 'football_recorder',
    'planner': 'football_planner',
    'view': 'football_view',
}
ROS_OWN = {'use_sim_time', 'start_type_description_service'}  # declared by rclpy itself


def _start_args(name, tmp_path):
    if name == 'view':  # any free port: a fixed one may be taken on a shared machine
        return ('view', '--port', '0')
    return ('record', '--out', str(tmp_path / 'bag')) if name == 'recorder' else (name,)


def test_reference_page_is_generated_from_the_tables():
    from football_ros.nodes.params import markdown

    page = (REPO / 'msg_docs' / 'parameters.md').read_text()
    assert page == markdown(node_tables()), (
        'stale: .venv/bin/python -m football_ros.nodes.reference > msg_docs/parameters.md'
    )


def test_config_file_lists_every_parameter_with_its_default():
    config = yaml.safe_load((REPO / 'config' / 'football.yaml').read_text())
    for name, table in node_tables().items():
        values = config[f'/**/{NODE_NAMES[name]}']['ros__parameters']
        assert list(values) == [spec.name for spec in table], name
        for spec in table:
            assert values[spec.name] == spec.default, (name, spec.name)


@pytest.mark.parametrize('name', list(NODES))
def test_help_lists_every_parameter_the_running_node_declares(
    name, start_node, collector, tmp_path
):
    node = start_node(*_start_args(name, tmp_path))
    listed = call(collector, ListParameters, f'/{NODE_NAMES[name]}/list_parameters',
                  ListParameters.Request()).result.names
    help_text = run_cli(name, '--help', timeout=60, check=True).stdout
    table = [spec.name for spec in node_tables()[name]]
    assert set(listed) - ROS_OWN == set(table)
    for spec_name in table:
        assert f'  {spec_name} (default ' in help_text, spec_name
    node.stop()


@pytest.mark.parametrize('name', list(NODES))
def test_an_unknown_option_is_an_error(name):
    proc = run_cli(name, '--foo', '--ros-args', timeout=60)
    assert proc.returncode == 2
    assert 'unrecognized arguments: --foo' in proc.stderr


def _set(collector, node, name, value, kind):
    field = {
        ParameterType.PARAMETER_INTEGER: 'integer_value',
        ParameterType.PARAMETER_DOUBLE: 'double_value',
        ParameterType.PARAMETER_STRING: 'string_value',
    }[kind]
    param = Parameter(name=name, value=ParameterValue(type=kind, **{field: value}))
    request = SetParameters.Request(parameters=[param])
    return call(collector, SetParameters, f'/{node}/set_parameters', request).results[0]


def test_integers_set_at_run_time_on_float_parameters_are_taken(start_node, collector):
    start_node('simulator', '--ros-args', '-p', 'allow_reconfigure:=true')
    result = _set(collector, 'football_simulator', 'publish_rate', 200,
                  ParameterType.PARAMETER_INTEGER)
    assert result.successful, result.reason
    start_node('release', '--ros-args', '-p', 'allow_reconfigure:=true')
    result = _set(collector, 'football_release', 'ack_timeout', 2,
                  ParameterType.PARAMETER_INTEGER)
    assert result.successful, result.reason
    described = call(
        collector, DescribeParameters, '/football_release/describe_parameters',
        DescribeParameters.Request(names=['ack_timeout', 'state_model']),
    ).descriptors
    assert described[0].type == ParameterType.PARAMETER_DOUBLE
    assert described[1].additional_constraints == 'one of: paper, full'
    # Out of range as an integer: refused by the range, not by the type.
    result = _set(collector, 'football_release', 'ack_timeout', 20,
                  ParameterType.PARAMETER_INTEGER)
    assert not result.successful and 'out of range' in result.reason.lower()
    result = _set(collector, 'football_release', 'state_model', 'bogus',
                  ParameterType.PARAMETER_STRING)
    assert not result.successful
    assert result.reason == "'state_model' must be one of paper, full, got 'bogus'"


def test_an_integer_override_of_a_float_parameter_is_taken_at_start_up(start_node, collector):
    start_node('release', '--ros-args', '-p', 'ack_timeout:=3')
    value = call(
        collector, GetParameters, '/football_release/get_parameters',
        GetParameters.Request(names=['ack_timeout']),
    ).values[0]
    assert value.type == ParameterType.PARAMETER_DOUBLE and value.double_value == 3.0


@pytest.mark.parametrize(
    'args, expected',
    [
        (('-p', 'state_model:=bogus'), "'state_model' must be one of paper, full, got 'bogus'"),
        (('-p', 'ack_timeout:=50'), 'ack_timeout'),
        (('-p', 'queue_depth:=1.5'), 'queue_depth'),
    ],
)
def test_a_bad_start_up_value_is_one_line_naming_the_parameter(args, expected):
    proc = run_cli('release', '--ros-args', *args, timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert expected in proc.stderr and 'Traceback' not in proc.stderr


@pytest.mark.parametrize('name', list(NODES))
def test_no_parameter_can_be_set_at_run_time_without_the_guard(name, start_node, collector,
                                                               tmp_path):
    """Every parameter the node lists (rclpy's own included) refuses a set of its own value."""
    start_node(*_start_args(name, tmp_path))
    node = NODE_NAMES[name]
    listed = call(collector, ListParameters, f'/{node}/list_parameters',
                  ListParameters.Request()).result.names
    assert 'use_sim_time' in listed
    values = call(collector, GetParameters, f'/{node}/get_parameters',
                  GetParameters.Request(names=listed)).values
    request = SetParameters.Request(parameters=[
        Parameter(name=n, value=v) for n, v in zip(listed, values)
    ])
    results = call(collector, SetParameters, f'/{node}/set_parameters', request).results
    accepted = [n for n, r in zip(listed, results) if r.successful]
    assert accepted == [], accepted
    [described] = call(collector, DescribeParameters, f'/{node}/describe_parameters',
                       DescribeParameters.Request(names=['use_sim_time'])).descriptors
    assert described.read_only


def test_use_sim_time_is_guarded_like_the_packages_parameters(start_node, collector):
    start_node('release', '--ros-args', '-p', 'use_sim_time:=true')
    value = call(collector, GetParameters, '/football_release/get_parameters',
                 GetParameters.Request(names=['use_sim_time'])).values[0]
    assert value.bool_value is True  # the start-up value is kept
    start_node('planner', '--ros-args', '-p', 'allow_reconfigure:=true')
    param = Parameter(name='use_sim_time',
                      value=ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=True))
    result = call(collector, SetParameters, '/football_planner/set_parameters',
                  SetParameters.Request(parameters=[param])).results[0]
    assert result.successful, result.reason
