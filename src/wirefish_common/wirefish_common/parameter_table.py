# SPDX-License-Identifier: Apache-2.0
"""
ROS parameters from one table: declaration with descriptors, and pure validation.

Each ``ParameterSpec`` is a name, a default (its type is the parameter's type), a description
and, for numbers, an inclusive range with an optional strict lower bound. ``check_value`` is the
pure validation a node runs in its ``add_on_set_parameters_callback``; ``declare`` builds the
``ParameterDescriptor`` with the matching ``FloatingPointRange`` / ``IntegerRange``. No rclpy
import at module level, so the validation is testable without ROS.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
import math
import re
from typing import Any, TYPE_CHECKING

if TYPE_CHECKING:  # rclpy only for the type checker: the validation stays importable without it
    from rclpy.node import Node
    from rclpy.parameter import Parameter

# Judges a whole set of values (see validate_update): a reason, or anything else for "fine".
Combination = Callable[[dict[str, object]], object]


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter: default (float, int, bool or str), description, range [low, high]."""

    name: str
    default: float | int | bool | str
    description: str
    low: float | None = None
    high: float | None = None
    low_exclusive: bool = False


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
        descriptor = ParameterDescriptor(description=spec.description)
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
