"""Pure validation of parameter values against their specs."""

import math

import pytest
from wirefish_common.parameter_table import check_value, ParameterSpec

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
