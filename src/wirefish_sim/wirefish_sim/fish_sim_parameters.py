# SPDX-License-Identifier: Apache-2.0
"""
fish_sim's parameters as one table (no rclpy import), and the rule of their combination.

The virtual fish swims the graph's one geometry block
(``wirefish_kinematics.geometry_parameters``), judged as every other node judges it
(``RULE``: ``geometry_from`` accepts the values). Its body does not change while it swims: each
value is read-only, taken at start-up.
"""

from __future__ import annotations

import dataclasses

from wirefish_common.parameter_table import builds, ParameterTable, Rule
from wirefish_kinematics.geometry_parameters import geometry_from, geometry_parameters

RULE: Rule = builds(geometry_from)
TABLE = ParameterTable(tuple(dataclasses.replace(spec, read_only=True)
                             for spec in geometry_parameters()), RULE)
