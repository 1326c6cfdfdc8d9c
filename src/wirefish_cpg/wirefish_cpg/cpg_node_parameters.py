"""
The cpg node's parameters as one table (no rclpy import).

The CPG's own parameters (eq 1) come from ``cpg_parameter_names``; the rest drive the node's
publish loop. Validation and declaration are the shared ones of ``wirefish_common``.
"""

from __future__ import annotations

import math

from wirefish_common.parameter_table import ParameterSpec
from wirefish_cpg.cpg_parameter_names import CPG_PARAMETERS

NODE_PARAMETERS = CPG_PARAMETERS + (
    # The default is the rate the fish receives: the bridge forwards at most its
    # max_command_rate_hz (100 Hz) to the board, so a faster stream is paid for by every
    # subscriber and then dropped at the gate. eq 1 is integrated at integration_step_s
    # whatever the publish rate, so the output at a publish instant does not depend on it.
    ParameterSpec('publish_rate_hz', 100.0,
                  'Rate of servo_cmd (Hz); the default is the rate the bridge forwards to the '
                  'board', 1.0, 1000.0),
    ParameterSpec('integration_step_s', 0.001,
                  'Fixed RK4 step of eq 1 (s), independent of the publish rate', 1e-5, 0.01),
    ParameterSpec('servo_limit_rad', math.pi / 2, 'Servo angle limit; outputs are clamped (rad)',
                  0.0, math.pi, low_exclusive=True),
    ParameterSpec('autostart', True, 'Start oscillating at launch (else wait for start)'),
)
SPECS = {spec.name: spec for spec in NODE_PARAMETERS}
