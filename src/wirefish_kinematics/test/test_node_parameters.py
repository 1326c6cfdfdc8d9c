"""The kinematics node's parameter table and its pure validation."""

import math
import subprocess
import sys

import pytest
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS
from wirefish_kinematics.node_parameters import (BODY_WAVE_GEOMETRY_FIELDS, check_value,
                                                 geometry_from, geometry_parameters, SPECS,
                                                 wave_from, WAVE_PARAMETER_NAMES)
from wirefish_kinematics.wave_spec import WaveSpec


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


def test_the_geometry_block_declares_the_fields_asked_for_with_the_node_specs():
    specs = geometry_parameters(BODY_WAVE_GEOMETRY_FIELDS)
    assert tuple(spec.name for spec in specs) == BODY_WAVE_GEOMETRY_FIELDS
    assert all(spec is SPECS[spec.name] for spec in specs)


def test_the_geometry_block_refuses_a_name_that_is_no_geometry_field():
    with pytest.raises(ValueError, match='wave_k'):
        geometry_parameters(('l1', 'wave_k'))


def test_a_partial_geometry_keeps_the_other_fields_at_their_defaults():
    geometry = geometry_from({'l1': 0.09, 'rd2': 0.02}, ('l1', 'rd2'))
    assert geometry == FishGeometry(l1=0.09, rd2=0.02)


def test_the_parameter_module_imports_no_rclpy():
    code = 'import sys, wirefish_kinematics.node_parameters; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
