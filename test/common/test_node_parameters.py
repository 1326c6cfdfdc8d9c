# SPDX-License-Identifier: Apache-2.0
"""NodeParameters on an rclpy node: declared, judged whole, kept, handed to the node, read."""

from collections.abc import Iterator, Mapping
from typing import Any

import pytest
from rclpy.parameter import Parameter
from wirefish_common.parameter_table import (InvalidParameters, NodeParameters, ParameterSpec,
                                             ParameterTable)

pytestmark = pytest.mark.ros


def _ordered(values: Mapping[str, Any]) -> str | None:
    return 'low_hz must be <= high_hz' if values['low_hz'] > values['high_hz'] else None


TABLE = ParameterTable((ParameterSpec('low_hz', 1.0, 'lower rate', 0.0, 10.0),
                        ParameterSpec('high_hz', 5.0, 'upper rate', 0.0, 10.0),
                        ParameterSpec('name', 'fish', 'a name')), _ordered)


@pytest.fixture
def node(ros_context) -> Iterator[Any]:
    """Yield a bare rclpy node on the test's own context."""
    from rclpy.node import Node

    made = Node('parameters_probe', context=ros_context)
    try:
        yield made
    finally:
        made.destroy_node()


@pytest.fixture
def bound(node) -> tuple[NodeParameters, list[tuple[frozenset[str], float]]]:
    """Return the table bound to ``node`` and the (names, low_hz seen) of each on_change."""
    calls: list[tuple[frozenset[str], float]] = []
    parameters = NodeParameters(node, TABLE, lambda names: calls.append(
        (names, parameters.float_value('low_hz'))))
    return parameters, calls


def test_a_set_the_rule_refuses_changes_nothing_and_says_why(node, bound):
    parameters, calls = bound
    result = node.set_parameters_atomically([Parameter('low_hz', value=7.0)])
    assert not result.successful and result.reason == 'low_hz must be <= high_hz'
    assert parameters.values['low_hz'] == node.get_parameter('low_hz').value == 1.0 and not calls


def test_an_accepted_set_is_kept_before_the_node_hears_its_names(node, bound):
    parameters, calls = bound
    result = node.set_parameters_atomically(
        [Parameter('high_hz', value=9.0), Parameter('low_hz', value=7.0)])
    assert result.successful
    assert calls == [(frozenset({'low_hz', 'high_hz'}), 7.0)]
    assert parameters.values['high_hz'] == 9.0


def test_a_name_outside_the_table_is_not_handed_to_the_node(node, bound):
    _, calls = bound
    node.declare_parameter('extra', 3)
    assert node.set_parameters([Parameter('extra', value=4)])[0].successful
    assert calls == []


def test_a_typed_read_of_another_type_is_refused(bound):
    parameters, _ = bound
    assert parameters.str_value('name') == 'fish'
    with pytest.raises(TypeError, match='name is a string parameter, not a double'):
        parameters.float_value('name')


def test_start_up_values_the_rule_refuses_name_the_node(ros_context):
    from rclpy.node import Node

    node = Node('refusing_probe', context=ros_context, parameter_overrides=[
        Parameter('low_hz', value=8.0)])
    try:
        with pytest.raises(InvalidParameters,
                           match='refusing_probe: invalid parameter: low_hz must be <= high_hz'):
            NodeParameters(node, TABLE)
    finally:
        node.destroy_node()
