# SPDX-License-Identifier: Apache-2.0
"""
The view node's parameters as one table (no rclpy import).

The scene's arcs need l1 and l2: the graph's one geometry block
(``wirefish_kinematics.geometry_parameters``), as the kinematics reads it. Each value stands
alone (``RULE`` is ``no_combination``). Validation and declaration are the shared ones of
``wirefish_common.parameter_table``.
"""

from __future__ import annotations

from wirefish_common.parameter_table import (no_combination, ParameterSpec, ParameterTable,
                                             Rule)
from wirefish_kinematics.geometry_parameters import geometry_parameters

RULE: Rule = no_combination
TABLE = ParameterTable((
    ParameterSpec('address', '127.0.0.1', 'Address the servers bind (127.0.0.1: this machine '
                  'only; 0.0.0.0 any: a warning is logged). Read at start'),
    ParameterSpec('port', 8765, 'Foxglove WebSocket port (0: any free one). Read at start',
                  0, 65535),
    ParameterSpec('http_port', 8080, 'Dashboard HTTP port (0: any free one; -1: none). Read '
                  'at start', -1, 65535),
    ParameterSpec('max_speed', 0.4, 'Largest cmd_vel linear.x a client may send (m/s)',
                  0.0, 2.0, low_exclusive=True),
    ParameterSpec('max_turn', 0.6, 'Largest |cmd_vel angular.z| a client may send (rad/s)',
                  0.0, 5.0, low_exclusive=True),
    ParameterSpec('scene_rate_hz', 10.0, 'Scene updates a second (Hz)', 0.0, 100.0,
                  low_exclusive=True),
    ParameterSpec('trail_length', 600, 'Positions kept in the trail', 2, 100000),
    ParameterSpec('discovery_period_s', 1.0, 'Seconds between looks for new topics', 0.0,
                  60.0, low_exclusive=True),
) + geometry_parameters(('l1', 'l2')), RULE)
