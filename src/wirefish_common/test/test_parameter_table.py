# SPDX-License-Identifier: Apache-2.0
"""Pure validation of parameter values against their specs."""

import math

import pytest
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.parameter import Parameter
from wirefish_common.parameter_table import (builds, check_value, merged_update,
                                             no_combination, ParameterSpec, ParameterTable,
                                             validate_update, wrong_type_reason)

RATE = ParameterSpec('rate', 50.0, 'a rate (Hz)', 0.0, 100.0, low_exclusive=True)
COUNT = ParameterSpec('count', 5, 'a count', 1, 10)
FLAG = ParameterSpec('flag', False, 'a switch')
PORT = ParameterSpec('port', '/dev/ttyUSB0', 'a device')


@pytest.mark.parametrize('spec, value', [
    (RATE, 0.0), (RATE, -1.0), (RATE, 100.5), (RATE, math.nan), (RATE, math.inf), (RATE, 'x'),
    (RATE, True), (COUNT, 0), (COUNT, 11), (COUNT, 2.5), (FLAG, 1), (FLAG, 'true'),
    (PORT, ''), (PORT, 3),
])
def test_invalid_values_are_refused_with_a_reason_naming_the_parameter(spec, value):
    reason = check_value(spec, value)
    assert reason is not None and spec.name in reason


@pytest.mark.parametrize('spec, value', [
    (RATE, 100.0), (RATE, 1e-9), (RATE, 50), (COUNT, 1), (COUNT, 10), (FLAG, True),
    (PORT, '/tmp/wirefish-tty'),
])
def test_values_inside_the_ranges_are_accepted(spec, value):
    assert check_value(spec, value) is None


def test_an_update_with_one_bad_value_is_refused_whole_and_changes_nothing():
    current = {'rate': 50.0, 'count': 5}
    merged, reason = merged_update({'rate': RATE, 'count': COUNT}, current,
                                   [('count', 7), ('rate', math.nan), ('use_sim_time', True)])
    assert reason is not None and 'rate' in reason
    assert current == {'rate': 50.0, 'count': 5}


def test_a_valid_update_is_merged_and_unknown_names_are_left_alone():
    merged, reason = merged_update({'rate': RATE}, {'rate': 50.0},
                                   [('rate', 20.0), ('use_sim_time', True)])
    assert reason is None and merged == {'rate': 20.0}


class _Param:
    def __init__(self, name, value):
        self.name, self.value = name, value


def _geometry(values):
    if values['rate'] > values['count'] * 10:
        raise ValueError('rate must not exceed 10 x count')
    return object()  # what a node builds from a consistent set


@pytest.mark.parametrize('updates, successful, reason_has', [
    ([('rate', 20.0)], True, ''),
    ([('rate', math.inf)], False, 'rate'),
    ([('rate', 80.0)], False, '10 x count'),
])
def test_validate_update_judges_values_then_their_combination(updates, successful, reason_has):
    result = validate_update({'rate': RATE, 'count': COUNT}, {'rate': 50.0, 'count': 5},
                             [_Param(*u) for u in updates], _geometry)
    assert result.successful == successful and reason_has in result.reason


def rclpy_wrong_type(name: str, value: object, expected: str) -> str:
    """Return the text of the exception rclpy raises for a start-up value of the wrong type."""
    return str(InvalidParameterTypeException(Parameter(name, value=value), expected).args[0])


@pytest.mark.parametrize('spec, value, expected, given', [
    (RATE, 2, 'must be a double (default 50.0)', "given an integer '2' (write 2.0)"),
    (COUNT, 'five', 'must be an integer (default 5)', "given a string 'five'"),
    (COUNT, 5.0, 'must be an integer (default 5)', "given a double '5.0'"),
    (FLAG, 1, 'must be a bool (default False)', "given an integer '1'"),
    (PORT, 3, "must be a string (default '/dev/ttyUSB0')", "given an integer '3'"),
])
def test_a_wrong_type_is_named_with_the_expected_and_the_given_type(spec, value, expected, given):
    line = wrong_type_reason('a_node', spec, rclpy_wrong_type(spec.name, value, 'X'))
    assert line == f'a_node: parameter {spec.name} {expected}, {given}'


def test_a_wrong_type_message_of_another_form_is_kept_whole():
    line = wrong_type_reason('a_node', RATE, 'something else went wrong')
    assert line == ('a_node: parameter rate must be a double (default 50.0): '
                    'something else went wrong')


def _ordered_count(values):
    if values['count'] > values['rate']:
        raise ValueError('count must be <= rate')
    return values['count']


def test_a_table_names_each_parameter_once():
    with pytest.raises(ValueError, match='parameters named twice in one table: rate'):
        ParameterTable((RATE, COUNT, RATE))


def test_a_table_judges_an_update_by_its_specs_then_its_rule():
    table = ParameterTable((RATE, COUNT), builds(_ordered_count))
    assert table.problem(table.defaults(), [('count', 7)]) is None
    reason = table.problem(table.defaults(), [('rate', 4.0), ('count', 7)])
    assert reason == 'count must be <= rate'
    assert 'count' in table.problem(table.defaults(), [('count', 0)])


def test_a_table_without_a_combination_judges_each_value_alone():
    table = ParameterTable((RATE, COUNT))
    assert table.rule is no_combination and table.names == ('rate', 'count')
    assert table.problem(table.defaults(), [('rate', 1.0), ('count', 10)]) is None
