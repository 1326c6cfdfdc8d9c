# SPDX-License-Identifier: Apache-2.0
"""The graph's one geometry block: FishGeometry's fields as ROS parameters."""

import subprocess
import sys

import pytest
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.geometry_parameters import (BODY_WAVE_GEOMETRY_FIELDS, geometry_from,
                                                     geometry_parameters)
from wirefish_kinematics.kinematics_node_parameters import TABLE

SPECS = TABLE.by_name


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


def test_the_geometry_block_imports_no_rclpy():
    code = ('import sys, wirefish_kinematics.geometry_parameters; '
            'sys.exit("rclpy" in sys.modules)')
    assert subprocess.run([sys.executable, '-c', code]).returncode == 0
