"""Pure validation of ROS parameter values against their specs."""

import math

import pytest
from wirefish_cpg.cpg_node import SPECS


@pytest.mark.parametrize('name, value', [
    ('frequency_hz', 0.0), ('frequency_hz', 10.5), ('frequency_hz', math.nan),
    ('amplitude_1', 2.0), ('offset_2', -math.inf), ('w12', 11.0), ('phi21', 3.2),
    ('alpha', 0.0), ('publish_rate_hz', 1001.0), ('integration_step_s', 0.1),
    ('servo_limit_rad', 0.0), ('autostart', 1.0), ('amplitude_2', 'big'),
    ('amplitude_2', True),
])
def test_invalid_values_are_refused_with_a_reason(name, value):
    from wirefish_common.parameter_table import check_value
    reason = check_value(SPECS[name], value)
    assert reason is not None and name in reason


@pytest.mark.parametrize('name, value', [
    ('frequency_hz', 10.0), ('amplitude_1', -math.pi / 2), ('w21', -10.0), ('phi12', math.pi),
    ('alpha', 200.0), ('publish_rate_hz', 1000.0), ('autostart', False),
])
def test_values_at_the_edges_of_the_ranges_are_accepted(name, value):
    from wirefish_common.parameter_table import check_value
    assert check_value(SPECS[name], value) is None
