# SPDX-License-Identifier: Apache-2.0
"""
The tf node's parameters as one table (no rclpy import), and the rule of their combination.

The geometry (l1, l2, l3, body_length) comes from the graph's one geometry block
(``wirefish_kinematics.geometry_parameters``). ``RULE``: ``consistent_geometry`` accepts the
values. Validation and declaration are the shared ones of ``wirefish_common.parameter_table``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from wirefish_common.parameter_table import builds, ParameterSpec, ParameterTable, Rule
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.geometry_parameters import geometry_from, geometry_parameters
from wirefish_tf.frames import OdomSource

GEOMETRY_NAMES = ('l1', 'l2', 'l3', 'body_length')
_SPECS = geometry_parameters(GEOMETRY_NAMES) + (
    ParameterSpec('odom_source', OdomSource.AUTO.value,
                  'Source of odom -> base_link: auto (ground truth once sim/ground_truth is '
                  'heard, else dead reckoning), ground_truth, dead_reckoning'),
    ParameterSpec('odom_rate_hz', 50.0, 'Most dead-reckoned odom -> base_link a second (Hz)',
                  0.0, 1000.0, low_exclusive=True),
    ParameterSpec('imu_x', -0.12, 'IMU position in base_link, x (m); estimate', -2.0, 2.0),
    ParameterSpec('imu_y', 0.0, 'IMU position in base_link, y (m); estimate', -1.0, 1.0),
    ParameterSpec('imu_z', 0.0, 'IMU position in base_link, z (m); estimate', -1.0, 1.0),
)


def consistent_geometry(values: Mapping[str, Any]) -> FishGeometry:
    """Return the geometry of ``values``; raise ValueError for an unknown ``odom_source``."""
    source = values.get('odom_source', OdomSource.AUTO.value)
    if source not in {s.value for s in OdomSource}:
        raise ValueError(f'odom_source must be one of {", ".join(s.value for s in OdomSource)},'
                         f' got {source!r}')
    return geometry_from(values, GEOMETRY_NAMES)


RULE: Rule = builds(consistent_geometry)
TABLE = ParameterTable(_SPECS, RULE)
