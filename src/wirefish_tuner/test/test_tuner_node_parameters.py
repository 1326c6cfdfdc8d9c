# SPDX-License-Identifier: Apache-2.0
"""The tuner node's parameter table: valid defaults, the body wave's geometry, no rclpy."""

import subprocess
import sys

from wirefish_common.parameter_table import check_value
from wirefish_kinematics.geometry import GEOMETRY_FIELDS
from wirefish_kinematics.geometry_parameters import (BODY_WAVE_GEOMETRY_FIELDS,
                                                     geometry_parameters)
from wirefish_tuner.feasibility import FitLimits
from wirefish_tuner.tuner_node_parameters import TABLE

SPECS = TABLE.by_name


def test_every_parameter_has_a_description_and_its_default_is_valid():
    for spec in TABLE:
        assert spec.description
        assert check_value(spec, spec.default) is None, spec.name


def test_the_geometry_is_the_body_waves_from_the_one_block():
    declared = tuple(spec for spec in TABLE if spec.name in GEOMETRY_FIELDS)
    assert declared == geometry_parameters(BODY_WAVE_GEOMETRY_FIELDS)


def test_the_fit_limits_defaults_are_fit_limits():
    limits = FitLimits()
    assert SPECS['servo_rate_limit_rad_s'].default == limits.servo_rate_limit_rad_s
    assert SPECS['min_frequency_hz'].default == limits.min_frequency_hz
    assert SPECS['max_rmse_deg'].default == limits.max_rmse_deg


def test_the_parameter_module_imports_no_rclpy():
    code = 'import sys, wirefish_tuner.tuner_node_parameters; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
