# SPDX-License-Identifier: Apache-2.0
"""The kinematics node's parameter table and its pure validation."""

import math
import subprocess
import sys

import pytest
from wirefish_common.parameter_table import check_value
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS
from wirefish_kinematics.geometry_parameters import geometry_from
from wirefish_kinematics.kinematics_node_parameters import TABLE, wave_from, WAVE_PARAMETER_NAMES
from wirefish_kinematics.wave_spec import WaveSpec

SPECS = TABLE.by_name


def test_every_parameter_has_a_description_and_its_default_is_valid():
    for spec in SPECS.values():
        assert spec.description
        assert check_value(spec, spec.default) is None, spec.name


def test_geometry_defaults_are_fish_geometry_defaults():
    values = {name: SPECS[name].default for name in GEOMETRY_FIELDS}
    assert geometry_from(values) == FishGeometry()


CASES = [
    ('l1', 0.0, '> 0'), ('r2', -0.01, '> 0'), ('drag_coefficient', math.nan, 'finite'),
    ('wave_k', 0.0, '> 0'), ('wave_frequency_hz', 11.0, '<= 10'),
    ('station_count', 1, '>= 2'), ('station_count', 2.5, 'integer'),
    ('publish_rate_hz', 'fast', 'number'), ('use_servo_state', 1, 'bool'),
]


@pytest.mark.parametrize('name, value, reason', CASES)
def test_invalid_values_are_refused_with_a_reason(name, value, reason):
    assert reason in check_value(SPECS[name], value)


def test_wave_defaults_are_wave_spec_defaults():
    values = {name: SPECS[name].default for name in WAVE_PARAMETER_NAMES}
    assert wave_from(values) == WaveSpec()


def test_the_parameter_module_imports_no_rclpy():
    code = ('import sys, wirefish_kinematics.kinematics_node_parameters; '
            'sys.exit("rclpy" in sys.modules)')
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
