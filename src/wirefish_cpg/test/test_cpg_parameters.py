# SPDX-License-Identifier: Apache-2.0
"""The CPG's flat ROS parameters: their one mapping to CpgParameters and their validation."""

import math
import subprocess
import sys

import pytest
from wirefish_common.parameter_table import check_value
from wirefish_cpg.cpg_messages import to_message
from wirefish_cpg.cpg_node_parameters import (CPG_PARAMETER_NAMES, CPG_PARAMETERS, flat_values,
                                              parameters_from, TABLE)
from wirefish_cpg.oscillator import at_rest, CpgParameters

SPECS = TABLE.by_name
TURNING = CpgParameters(frequency_hz=2.5, amplitude=(0.3, -0.2), offset=(0.1, -0.05),
                        w12=1.5, w21=-2.0, phi12=-0.5, phi21=2.0, alpha=30.0)


@pytest.mark.parametrize('name, value', [
    ('frequency_hz', 0.0), ('frequency_hz', 10.5), ('frequency_hz', math.nan),
    ('amplitude_1', 2.0), ('offset_2', -math.inf), ('w12', 11.0), ('phi21', 3.2),
    ('alpha', 0.0), ('publish_rate_hz', 1001.0), ('integration_step_s', 0.1),
    ('servo_limit_rad', 0.0), ('autostart', 1.0), ('amplitude_2', 'big'),
    ('amplitude_2', True),
])
def test_invalid_values_are_refused_with_a_reason(name, value):
    reason = check_value(SPECS[name], value)
    assert reason is not None and name in reason


@pytest.mark.parametrize('name, value', [
    ('frequency_hz', 10.0), ('amplitude_1', -math.pi / 2), ('w21', -10.0), ('phi12', math.pi),
    ('alpha', 200.0), ('publish_rate_hz', 1000.0), ('autostart', False),
])
def test_values_at_the_edges_of_the_ranges_are_accepted(name, value):
    assert check_value(SPECS[name], value) is None


@pytest.mark.parametrize('params', [CpgParameters(), TURNING])
def test_flat_values_map_back_to_the_same_parameters(params):
    assert parameters_from(flat_values(params)) == params


def test_flat_names_follow_the_fields_of_cpg_parameters():
    assert flat_values(TURNING) == {
        'frequency_hz': 2.5, 'amplitude_1': 0.3, 'amplitude_2': -0.2, 'offset_1': 0.1,
        'offset_2': -0.05, 'w12': 1.5, 'w21': -2.0, 'phi12': -0.5, 'phi21': 2.0, 'alpha': 30.0}


def test_the_parameter_defaults_are_those_of_cpg_parameters():
    assert {spec.name: spec.default for spec in CPG_PARAMETERS} == flat_values(CpgParameters())


def test_every_cpg_parameter_is_a_node_parameter_in_the_mapping_order():
    assert tuple(spec.name for spec in CPG_PARAMETERS) == CPG_PARAMETER_NAMES
    assert set(CPG_PARAMETER_NAMES) <= set(SPECS)


def test_a_missing_name_is_a_key_error_naming_it():
    values = flat_values(TURNING)
    del values['offset_2']
    with pytest.raises(KeyError, match='offset_2'):
        parameters_from(values)


def test_at_rest_zeroes_only_the_amplitude_and_offset_targets():
    rest = at_rest(TURNING)
    assert (rest.amplitude, rest.offset) == ((0.0, 0.0), (0.0, 0.0))
    assert flat_values(rest) | {'amplitude_1': 0.3, 'amplitude_2': -0.2, 'offset_1': 0.1,
                                'offset_2': -0.05} == flat_values(TURNING)


def test_the_message_carries_every_parameter():
    msg = to_message(TURNING)
    assert (msg.frequency_hz, msg.w12, msg.w21, msg.phi12, msg.phi21, msg.alpha) == (
        2.5, 1.5, -2.0, -0.5, 2.0, 30.0)
    assert (list(msg.amplitude), list(msg.offset)) == ([0.3, -0.2], [0.1, -0.05])


def test_the_parameter_module_imports_no_rclpy():
    code = 'import sys, wirefish_cpg.cpg_node_parameters; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
