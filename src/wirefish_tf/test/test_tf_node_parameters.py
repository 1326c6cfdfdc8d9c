# SPDX-License-Identifier: Apache-2.0
"""The tf node's parameter table and the rule of their combination (pure)."""

import subprocess
import sys

import pytest
from wirefish_common.parameter_table import check_value
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.geometry_parameters import geometry_parameters
from wirefish_tf.tf_node_parameters import consistent_geometry, GEOMETRY_NAMES, TABLE

SPECS = TABLE.by_name


def _defaults():
    return {spec.name: spec.default for spec in TABLE}


def test_every_parameter_has_a_description_and_its_default_is_valid():
    for spec in TABLE:
        assert spec.description
        assert check_value(spec, spec.default) is None, spec.name


def test_the_defaults_give_the_default_geometry():
    assert consistent_geometry(_defaults()) == FishGeometry()


def test_a_changed_length_reaches_the_geometry():
    assert consistent_geometry({**_defaults(), 'l2': 0.12}).l2 == 0.12


def test_an_unknown_odom_source_is_refused_with_the_known_ones():
    with pytest.raises(ValueError, match='dead_reckoning'):
        consistent_geometry({**_defaults(), 'odom_source': 'gps'})


def test_the_geometry_is_declared_from_the_one_geometry_block():
    assert tuple(SPECS[name] for name in GEOMETRY_NAMES) == geometry_parameters(GEOMETRY_NAMES)


def test_the_parameter_module_imports_no_rclpy():
    code = 'import sys, wirefish_tf.tf_node_parameters; sys.exit("rclpy" in sys.modules)'
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
