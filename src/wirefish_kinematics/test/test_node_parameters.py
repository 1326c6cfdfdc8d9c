"""The kinematics node's parameter table and its pure validation."""

import math

import pytest
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS
from wirefish_kinematics.node_parameters import check_value, geometry_from, SPECS


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
