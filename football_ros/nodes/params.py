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
Node parameters: one table (:class:`ParamSpec` rows) per node, the source of everything.

From a node's ``PARAMETERS`` table come its declarations (descriptor: description, range,
choices, read-only), its start-up checks, its ``--help`` lines (nodes/runner.py) and the
parameter reference (msg_docs/parameters.md, written by :func:`markdown`). Integers are taken
for float parameters, at start-up (``-p publish_rate:=200``) and at run time (``ros2 param set
/football_simulator publish_rate 200``), as rclcpp users expect.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Sequence

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
)
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.node import Node
from rclpy.parameter import Parameter

from ..physics.release import exact

MAX_STRING = 256
"""Characters a string parameter may hold (frame ids, names, paths): a bound on every copy."""
GUARD = 'allow_reconfigure'
"""The parameter that guards a row with ``guard=GUARD`` (read-only: set at start-up only)."""


@dataclass(frozen=True)
class ParamSpec:
    """
    One parameter: name, default (its type is the parameter's), description, rules.

    ``limits``: inclusive numeric range (enforced by the descriptor); ``choices``: the values a
    string may take (listed in the descriptor's additional_constraints, checked on every set);
    ``read_only``: fixed after start-up; ``non_empty``: a string that must not be '';
    ``optional``: may be left unset (``null`` or ``[]`` in a params file), meaning the default.
    ``guard``: the name of the start-up-only boolean (:data:`GUARD`) without which the row is
    read-only at run time: a stranger on the domain cannot change it with ``ros2 param set``
    unless the node was started with ``-p allow_reconfigure:=true``.
    """

    name: str
    default: object
    description: str
    limits: tuple[float, float] | None = None
    choices: tuple[str, ...] | None = None
    read_only: bool = False
    non_empty: bool = False
    optional: bool = False
    guard: str | None = None

    def __post_init__(self) -> None:
        """Refuse a guard that is not in :data:`GUARDS`."""
        if self.guard is not None and self.guard not in GUARDS:
            raise ValueError(f'{self.name}: unknown guard {self.guard!r} (one of {GUARDS})')

    def descriptor(self, writable: bool = True) -> ParameterDescriptor:
        """
        Return the ParameterDescriptor that ``ros2 param describe`` shows.

        ``writable``: the guard's value on the node (a guarded row is read-only without it).
        """
        read_only = self.read_only or (self.guard is not None and not writable)
        descriptor = ParameterDescriptor(
            description=self.description, read_only=read_only, dynamic_typing=self.optional
        )
        if self.choices:
            descriptor.additional_constraints = f'one of: {", ".join(self.choices)}'
        elif self.non_empty:
            descriptor.additional_constraints = 'must not be empty'
        if read_only and not self.read_only:  # by the guard
            rule = f'read-only unless the node is started with {self.guard}:=true'
            before = descriptor.additional_constraints
            descriptor.additional_constraints = f'{before}; {rule}' if before else rule
        if self.limits is not None:
            lo, hi = self.limits
            if isinstance(self.default, bool) or not isinstance(self.default, (int, float)):
                raise TypeError(f'{self.name}: only a number takes a range')
            if isinstance(self.default, int):
                descriptor.integer_range = [
                    IntegerRange(from_value=int(lo), to_value=int(hi), step=1)
                ]
            else:
                descriptor.floating_point_range = [
                    FloatingPointRange(from_value=float(lo), to_value=float(hi), step=0.0)
                ]
        return descriptor

    def check(self, value: object) -> str | None:
        """Why ``value`` is refused (the rules the descriptor cannot enforce), or None."""
        if isinstance(value, list):
            return next(filter(None, (self.check(v) for v in value)), None)
        if isinstance(value, str):
            if len(value) > MAX_STRING:
                return f"'{self.name}' must be at most {MAX_STRING} characters"
            if self.choices and value not in self.choices:
                return (
                    f"'{self.name}' must be one of {', '.join(self.choices)}, "
                    f'got {value[:40]!r}'
                )
            if self.non_empty and not value:
                return f"'{self.name}' must not be empty"
        return None

    def declare(self, node: Node):
        """
        Declare on ``node``; return the value in force (default or override).

        A guarded row first declares its guard (if the node has not yet) and is declared
        read-only unless the guard is true: rclpy then refuses a run-time set before any
        on-set callback runs, whatever the order of the node's callbacks.
        Raises ValueError naming the parameter for a value the rules refuse.
        """
        if self.name in GUARDS and node.has_parameter(self.name):
            return node.get_parameter(self.name).value  # declared by a guarded row before
        writable = True
        if self.guard is not None:
            if not node.has_parameter(self.guard):
                GUARDS[self.guard].declare(node)
            writable = node.get_parameter(self.guard).value is True
        descriptor = self.descriptor(writable)
        try:
            value = node.declare_parameter(self.name, self.default, descriptor).value
            if self.optional:
                value = self._typed(value)
        except InvalidParameterTypeException:
            if not isinstance(self.default, float):
                raise
            value = _integer_override(node, self, descriptor)
        reason = self.check(value)
        if reason:
            raise ValueError(f'parameter {reason}')
        return value

    def _typed(self, value: object) -> object:
        """Return an optional parameter's value: the default when unset, else of its type."""
        if value is None:
            return self.default
        if isinstance(self.default, list) and isinstance(value, str):
            value = [value]  # one name for a list of names
        if isinstance(self.default, list):
            ok = isinstance(value, list) and all(isinstance(v, str) for v in value)
        else:
            ok = type(value) is type(self.default)
        if not ok:
            kind = 'a list of strings' if isinstance(self.default, list) else 'a string'
            raise ValueError(f"parameter '{self.name}' must be {kind}, got {value!r:.60}")
        return value

    def help_line(self) -> str:
        """One ``--help`` line: name, default, range or choices, description."""
        return (
            f'  {self.name} (default {self.default!r}{self._rules()}): {self.description}'
            + self._guarded()
        )

    def _guarded(self) -> str:
        return f' (guarded: {self.guard})' if self.guard and not self.read_only else ''

    def _rules(self) -> str:
        rules = []
        if self.limits:
            rules.append(f'{exact(self.limits[0])} .. {exact(self.limits[1])}')
        if self.choices:
            rules.append(' | '.join(self.choices))
        if self.read_only:
            rules.append('read-only')
        return f' [{", ".join(rules)}]' if rules else ''


GUARDS = {
    GUARD: ParamSpec(
        GUARD,
        False,
        'Let the guarded parameters be changed at run time (ros2 param set); start-up only',
        read_only=True,
    ),
}
"""Guard name -> its row (declared by the first guarded row of a node that lacks it)."""
BUILTINS = (
    ParamSpec(
        'use_sim_time',
        False,
        "rclpy's own: time from /clock (true) or the wall clock (false)",
        guard=GUARD,
    ),
)
"""rclpy's own parameters that change behaviour and that rclpy leaves writable: guarded like
the package's rows (read-only unless the guard is true; read-only on a node without the guard).
rclpy declares its other ones (``start_type_description_service``, ``qos_overrides.*``)
read-only."""


def with_guards(specs: Sequence[ParamSpec]) -> tuple[ParamSpec, ...]:
    """Return ``specs`` with the guards its rows name first (those not in it): what is declared."""
    names = {spec.name for spec in specs}
    named = dict.fromkeys(s.guard for s in specs if s.guard is not None and s.guard not in names)
    return tuple(GUARDS[g] for g in named) + tuple(specs)


def _integer_override(node: Node, spec: ParamSpec, descriptor: ParameterDescriptor):
    """
    Take an integer override of a float parameter as that float.

    The override is read through a dynamically typed declaration that is then replaced by the
    typed one (public rclpy API only); any other type is refused as rclpy refuses it.
    """
    probe = node.declare_parameter(
        spec.name, spec.default, ParameterDescriptor(dynamic_typing=True)
    ).value
    node.undeclare_parameter(spec.name)
    if isinstance(probe, bool) or not isinstance(probe, (int, float)):
        raise InvalidParameterTypeException(
            Parameter(spec.name, value=probe), Parameter.Type.DOUBLE.name
        )
    return node.declare_parameter(
        spec.name, float(probe), descriptor, ignore_override=True
    ).value


def declare_all(node: Node, specs: Sequence[ParamSpec]) -> dict[str, object]:
    """
    Declare every row of ``specs`` on ``node`` and set each value as an attribute of it.

    Also guards rclpy's own parameters (:func:`guard_builtins`) and installs the checks of
    :meth:`ParamSpec.check` on every later set, the callback that takes integers for float
    parameters, and one that sets the attributes of what a set put in force. Returns
    {name: value}.
    """
    values = {}
    for spec in specs:
        values[spec.name] = spec.declare(node)
        setattr(node, spec.name, values[spec.name])
    table = {spec.name: spec for spec in specs}
    writable = guard_builtins(node)

    def check(params: list[Parameter]) -> SetParametersResult:
        for p in params:
            spec = table.get(p.name)
            # Any other declared parameter (rclpy's own) is guarded; declarations pass.
            if spec is None and not writable and node.has_parameter(p.name):
                return SetParametersResult(
                    successful=False,
                    reason=f"'{p.name[:100]}' is read-only at run time (the node was not "
                    f'started with {GUARD}:=true)',
                )
            reason = spec.check(p.value) if spec is not None else None
            if reason:
                return SetParametersResult(successful=False, reason=reason)
        return SetParametersResult(successful=True)

    def apply(params: list[Parameter]) -> None:
        for p in params:
            if p.name in table:
                setattr(node, p.name, p.value)

    node.add_on_set_parameters_callback(check)
    node.add_post_set_parameters_callback(apply)
    accept_integers_for_floats(node)
    return values


def guard_builtins(node: Node) -> bool:
    """
    Redeclare each of :data:`BUILTINS` on ``node`` read-only unless its guard is true.

    The value in force is kept (rclpy's time source goes on reading it). Returns whether the
    guard is true (False on a node without the guard).
    """
    writable = node.has_parameter(GUARD) and node.get_parameter(GUARD).value is True
    guarded = node.has_parameter(GUARD)
    for spec in BUILTINS:
        if not guarded:
            spec = replace(spec, guard=None, read_only=True)
        if node.has_parameter(spec.name):
            value = node.get_parameter(spec.name).value
            node.undeclare_parameter(spec.name)
            node.declare_parameter(
                spec.name, value, spec.descriptor(writable), ignore_override=True
            )
    return writable


def accept_integers_for_floats(node: Node) -> None:
    """Turn an integer set on a float parameter into that float before rclpy's type check."""
    if getattr(node, '_football_ros_integers_accepted', False):
        return
    node._football_ros_integers_accepted = True

    def convert(params: list[Parameter]) -> list[Parameter]:
        out = []
        for p in params:
            if p.type_ == Parameter.Type.INTEGER and node.has_parameter(p.name):
                declared = node.describe_parameter(p.name)
                if declared.type == ParameterType.PARAMETER_DOUBLE:
                    p = Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
            out.append(p)
        return out

    node.add_pre_set_parameters_callback(convert)


def markdown(tables: dict[str, Sequence[ParamSpec]]) -> str:
    """Return the parameter reference of every node (msg_docs/parameters.md)."""
    lines = [
        '# Parameters',
        '',
        "Generated from the nodes' parameter tables (`python -m football_ros.nodes.reference`);",
        "do not edit by hand. Each node's `--help` prints the same table. Integers are accepted",
        'for float parameters (`-p publish_rate:=200`, `ros2 param set ... publish_rate 200`).',
        f'A row *(guarded: {GUARD})* is read-only at run time unless the node is started with',
        f'`-p {GUARD}:=true` (launch: `{GUARD}:=true`): by default no other participant on the',
        'domain can change it with `ros2 param set`. A read-only row is set at start-up only.',
        "rclpy's own `use_sim_time` is guarded the same way (read-only on a node without the",
        "guard); rclpy declares its other ones read-only; every parameter not in a node's table",
        'is refused at run time unless the guard is true.',
    ]
    for node, specs in tables.items():
        lines += ['', f'## {node}', '', '| name | default | range / choices | description |',
                  '|---|---|---|---|']
        for spec in specs:
            rules = spec._rules().strip(' []').replace('|', '\\|')
            default = repr(spec.default).replace('|', '\\|')
            text = spec.description + spec._guarded()
            lines.append(f'| `{spec.name}` | `{default}` | {rules} | {text} |')
    return '\n'.join(lines) + '\n'
