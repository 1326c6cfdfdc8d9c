# SPDX-License-Identifier: Apache-2.0
"""
ROS parameters from one table: declaration with descriptors, and pure validation.

Each ``ParameterSpec`` is a name, a default (its type is the parameter's type), a description
and, for numbers, an inclusive range with an optional strict lower bound. A node's
``ParameterTable`` is its specs and the ``Rule`` of their combination (``<node>_parameters``
exports it as ``TABLE``, the rule as ``RULE``). ``NodeParameters`` is the one way a node takes
its table: it declares every spec (``declare``: a ``ParameterDescriptor`` with the matching
``FloatingPointRange`` / ``IntegerRange``), keeps the current values, judges every update
whole against the specs and the rule (``update_problem``: refused with the reason, nothing
changed) and hands the accepted names to the node. No rclpy import at module level, so the
tables and their validation are testable without ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
import math
import re
from types import MappingProxyType
from typing import Any, TYPE_CHECKING

if TYPE_CHECKING:  # rclpy only for the type checker: the validation stays importable without it
    from rclpy.node import Node
    from rclpy.parameter import Parameter

# Judges a whole set of values (see validate_update): a reason, or anything else for "fine".
Combination = Callable[[dict[str, object]], object]
# The rule of a table's combination: why a whole set of values (name -> value, every name of the
# table) is refused, or None. Pure, so a refusal is testable without a node.
Rule = Callable[[Mapping[str, Any]], str | None]


@dataclass(frozen=True)
class ParameterSpec:
    """
    A parameter: default (float, int, bool or str), description, range [low, high].

    ``read_only``: taken once at start-up (a file, ``-p``); ROS refuses a later set.
    """

    name: str
    default: float | int | bool | str
    description: str
    low: float | None = None
    high: float | None = None
    low_exclusive: bool = False
    read_only: bool = False


def check_value(spec: ParameterSpec, value: object) -> str | None:
    """Return why ``value`` is not acceptable for ``spec``, or None if it is."""
    kind = type(spec.default)
    if kind is bool or kind is str:
        if type(value) is not kind:
            return f'{spec.name} must be a {kind.__name__}, got {value!r}'
        if kind is str and not value:
            return f'{spec.name} must not be empty'
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f'{spec.name} must be a number, got {value!r}'
    if kind is int and not isinstance(value, int):
        return f'{spec.name} must be an integer, got {value!r}'
    if not math.isfinite(value):
        return f'{spec.name} must be finite, got {value}'
    if spec.low is not None:
        if spec.low_exclusive and value <= spec.low:
            return f'{spec.name} must be > {spec.low:g}, got {value:g}'
        if value < spec.low:
            return f'{spec.name} must be >= {spec.low:g}, got {value:g}'
    if spec.high is not None and value > spec.high:
        return f'{spec.name} must be <= {spec.high:g}, got {value:g}'
    return None


class InvalidParameters(ValueError):
    """The values a node starts with (defaults, YAML, --ros-args -p) are refused."""


# The ROS names of the parameter types (as `ros2 param describe` shows them).
ROS_TYPE_NAMES = {bool: 'bool', int: 'integer', float: 'double', str: 'string'}
# What rclpy's InvalidParameterTypeException says; its exception carries no separate fields.
_RCLPY_WRONG_TYPE = re.compile(r"to '(?P<value>.*)' of type '(?P<type>\w+)', expecting type")


def _article(word: str) -> str:
    return 'an' if word[:1] in 'aeiou' else 'a'


def wrong_type_reason(node_name: str, spec: ParameterSpec, rclpy_reason: str) -> str:
    """
    Return the one line for a start-up value whose type is not the parameter's.

    ``rclpy_reason`` is the text of rclpy's ``InvalidParameterTypeException``; the value and
    its type are taken from it (it is kept whole if it does not have rclpy's usual form).
    """
    expected = ROS_TYPE_NAMES[type(spec.default)]
    line = (f'{node_name}: parameter {spec.name} must be {_article(expected)} {expected} '
            f'(default {spec.default!r})')
    match = _RCLPY_WRONG_TYPE.search(rclpy_reason)
    if match is None:
        return f'{line}: {rclpy_reason}'
    given = match['type'].lower()
    line += f", given {_article(given)} {given} '{match['value']}'"
    if expected == 'double' and given == 'integer':
        line += f" (write {match['value']}.0)"
    return line


def declare(node: Node, specs: tuple[ParameterSpec, ...],
            combination: Combination | None = None) -> None:
    """
    Declare every spec on ``node`` with a descriptor carrying its description and range.

    The values the node starts with (a parameter file or ``-p`` may override the defaults) are
    then judged as a later update would be: each against its spec, then ``combination`` (see
    ``validate_update``). Raises ``InvalidParameters`` naming the node and the first reason, so
    a node never runs on values it would refuse in a ``ros2 param set``.
    """
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
    from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException

    for spec in specs:
        descriptor = ParameterDescriptor(description=spec.description, read_only=spec.read_only)
        if spec.low is not None and spec.high is not None:
            if type(spec.default) is float:
                descriptor.floating_point_range = [FloatingPointRange(
                    from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
            elif type(spec.default) is int:
                descriptor.integer_range = [IntegerRange(
                    from_value=int(spec.low), to_value=int(spec.high), step=1)]
        if spec.low_exclusive:
            descriptor.additional_constraints = f'> {spec.low:g}'
        try:
            node.declare_parameter(spec.name, spec.default, descriptor)
        except InvalidParameterValueException as error:  # rclpy's own range check
            raise InvalidParameters(f'{node.get_name()}: {error}') from error
        except InvalidParameterTypeException as error:  # e.g. -p frequency_hz:=2 for a double
            raise InvalidParameters(
                wrong_type_reason(node.get_name(), spec, str(error.args[0]))) from error
    values = [(spec.name, node.get_parameter(spec.name).value) for spec in specs]
    reason = update_problem({spec.name: spec for spec in specs}, {}, values, combination)
    if reason is not None:
        raise InvalidParameters(f'{node.get_name()}: invalid parameter: {reason}')


def merged_update(specs: dict[str, ParameterSpec], current: dict[str, object],
                  updates: list[tuple[str, object]]) -> tuple[dict[str, object], str | None]:
    """
    Return (``current`` with ``updates`` applied, the first reason to refuse them or None).

    What a node's ``add_on_set_parameters_callback`` does before it checks the combination:
    every value is checked against its spec; names outside ``specs`` (e.g. ``use_sim_time``)
    are left to rclpy.
    """
    merged = dict(current)
    for name, value in updates:
        spec = specs.get(name)
        if spec is None:
            continue
        reason = check_value(spec, value)
        if reason is not None:
            return merged, reason
        merged[name] = value
    return merged, None


def validate_update(specs: dict[str, ParameterSpec], current: dict[str, object],
                    parameters: Sequence[Parameter],
                    combination: Combination | None = None) -> Any:
    """
    Return the ``SetParametersResult`` of a node's ``add_on_set_parameters_callback``.

    ``parameters`` are rclpy ``Parameter`` objects. Every value is checked against its spec,
    then ``combination(merged values)`` (if given) judges the whole set: a string it returns, or
    the message of a ``ValueError`` it raises, is the reason; anything else it returns (None, or
    the object it built from the values) means the set is consistent. The whole set is rejected
    with the first reason, so an invalid update changes nothing.
    """
    from rcl_interfaces.msg import SetParametersResult

    reason = update_problem(specs, current, [(p.name, p.value) for p in parameters],
                            combination)
    return SetParametersResult(successful=reason is None, reason=reason or '')


def update_problem(specs: dict[str, ParameterSpec], current: dict[str, object],
                   updates: list[tuple[str, object]],
                   combination: Combination | None = None) -> str | None:
    """Return the first reason to refuse ``updates`` (values, then their combination), or None."""
    merged, reason = merged_update(specs, current, updates)
    if reason is None and combination is not None:
        try:
            verdict = combination(merged)
            reason = verdict if isinstance(verdict, str) else None
        except ValueError as error:
            reason = str(error)
    return reason


def no_combination(values: Mapping[str, Any]) -> str | None:
    """Return None: the rule of a table whose values each stand alone (their specs judge them)."""
    return None


def builds(build: Callable[[Mapping[str, Any]], object]) -> Rule:
    """
    Return the rule "``build(values)`` succeeds": the message of its ``ValueError`` is the reason.

    For a table whose values make one object together (``CpgParameters``, ``FishGeometry``, a
    ``Planner``): the object's own checks are the combination's, written once.
    """
    def rule(values: Mapping[str, Any]) -> str | None:
        try:
            build(values)
        except ValueError as error:
            return str(error)
        return None

    rule.__name__ = rule.__qualname__ = f'builds({getattr(build, "__name__", build)})'
    return rule


@dataclass(frozen=True)
class ParameterTable:
    """A node's parameters: the specs in declaration order, and the rule of their combination."""

    specs: tuple[ParameterSpec, ...]
    rule: Rule = no_combination
    by_name: Mapping[str, ParameterSpec] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        """Refuse a name given twice (the node could not declare it); index the specs by name."""
        names = [spec.name for spec in self.specs]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise ValueError(f'parameters named twice in one table: {", ".join(repeated)}')
        object.__setattr__(self, 'by_name',
                           MappingProxyType({spec.name: spec for spec in self.specs}))

    def __iter__(self) -> Iterator[ParameterSpec]:
        """Iterate over the specs, in declaration order."""
        return iter(self.specs)

    @property
    def names(self) -> tuple[str, ...]:
        """Return the parameters' names, in declaration order."""
        return tuple(spec.name for spec in self.specs)

    def defaults(self) -> dict[str, Any]:
        """Return the parameters' defaults by name."""
        return {spec.name: spec.default for spec in self.specs}

    def problem(self, current: Mapping[str, object],
                updates: Sequence[tuple[str, object]]) -> str | None:
        """Return why ``updates`` of ``current`` are refused (values, then the rule), or None."""
        return update_problem(dict(self.by_name), dict(current), list(updates), self.rule)


class NodeParameters:
    """
    The parameters of one ``ParameterTable`` on one node: declared, kept, judged and applied.

    Building it declares the table (``declare``: a refused start-up value raises
    ``InvalidParameters``) and keeps the values the node starts with. Then every update is
    judged whole, each value against its spec and then the table's rule over the values it
    would make; a refused one changes nothing and its reason is the answer. An accepted one is
    kept here first, then ``on_change`` gets the names of the table it changed (never an empty
    set: ``use_sim_time`` or ``frame_prefix`` alone are not the table's). The callbacks are
    registered after the declaration: rclpy runs them on every ``declare_parameter`` too, and a
    name outside the table (``frame_prefix`` declared later) is left to rclpy.
    """

    def __init__(self, node: Node, table: ParameterTable,
                 on_change: Callable[[frozenset[str]], None] | None = None) -> None:
        """Declare ``table`` on ``node``, keep its values, register the set callbacks."""
        declare(node, table.specs, table.rule)
        self.table = table
        self._node = node
        self._specs = dict(table.by_name)
        self._current: dict[str, Any] = {
            name: node.get_parameter(name).value for name in table.names}
        # Read-only and live: whoever holds it reads the values as they are now.
        self.values: Mapping[str, Any] = MappingProxyType(self._current)
        self._on_change = on_change
        node.add_on_set_parameters_callback(self._judge)
        node.add_post_set_parameters_callback(self._take)

    def _judge(self, parameters: list[Parameter]) -> Any:
        return validate_update(self._specs, self._current, parameters, self.table.rule)

    def _take(self, parameters: list[Parameter]) -> None:
        names = frozenset(p.name for p in parameters if p.name in self._specs)
        for name in names:
            self._current[name] = self._node.get_parameter(name).value
        if names and self._on_change is not None:
            self._on_change(names)

    def _typed(self, name: str, kind: type) -> Any:
        spec = self.table.by_name.get(name)
        if spec is None:
            raise KeyError(f'{name} is no parameter of this table')
        if type(spec.default) is not kind:
            raise TypeError(f'{name} is {_article(ROS_TYPE_NAMES[type(spec.default)])} '
                            f'{ROS_TYPE_NAMES[type(spec.default)]} parameter, not '
                            f'{_article(ROS_TYPE_NAMES[kind])} {ROS_TYPE_NAMES[kind]}')
        return self._current[name]

    def float_value(self, name: str) -> float:
        """Return the current value of the double parameter ``name``."""
        return float(self._typed(name, float))

    def int_value(self, name: str) -> int:
        """Return the current value of the integer parameter ``name``."""
        return int(self._typed(name, int))

    def bool_value(self, name: str) -> bool:
        """Return the current value of the bool parameter ``name``."""
        return bool(self._typed(name, bool))

    def str_value(self, name: str) -> str:
        """Return the current value of the string parameter ``name``."""
        return str(self._typed(name, str))
