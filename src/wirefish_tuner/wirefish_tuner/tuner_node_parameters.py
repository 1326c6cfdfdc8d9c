# SPDX-License-Identifier: Apache-2.0
"""
The tuner node's parameters as one table (no rclpy import).

The geometry is that of the body wave (``l1`` ... ``rd2``: all a fit needs), from the graph's
one geometry block (``wirefish_kinematics.geometry_parameters``); the fit limits' defaults are
``FitLimits()``'s and the PSO bounds ``retune_core``'s. Each value stands alone (``RULE`` is
``no_combination``): a fit judges its settings when it starts. Validation and declaration are
the shared ones of ``wirefish_common.parameter_table``.
"""

from __future__ import annotations

import math

from wirefish_common.parameter_table import (no_combination, ParameterSpec, ParameterTable,
                                             Rule)
from wirefish_cpg.gait_library import default_library_path
from wirefish_kinematics.geometry_parameters import (BODY_WAVE_GEOMETRY_FIELDS,
                                                     geometry_parameters)
from wirefish_tuner.feasibility import FitLimits
from wirefish_tuner.retune_core import MAX_ITERATIONS, MAX_SWARM_SIZE

_LIMITS = FitLimits()
RULE: Rule = no_combination
TABLE = ParameterTable((
    ParameterSpec('cpg_node_name', 'cpg_node',
                  'Name (relative or absolute) of the CPG node whose parameters apply sets'),
    ParameterSpec('swarm_size', 40, 'Default PSO particles per run', 2, MAX_SWARM_SIZE),
    ParameterSpec('max_iterations', 100, 'Default PSO iteration limit', 1, MAX_ITERATIONS),
    ParameterSpec('stall_iterations', 20, 'Stop after this many iterations without gain', 1,
                  5000),
    ParameterSpec('stall_tolerance', 1e-6, 'Relative gain below which an iteration stalls',
                  0.0, 1.0),
    ParameterSpec('inertia', 0.7298, 'PSO inertia weight c_w, eq 26', 0.0, 2.0),
    ParameterSpec('cognitive', 1.49618, 'PSO learning factor c_f1, eq 26', 0.0, 4.0),
    ParameterSpec('social', 1.49618, 'PSO learning factor c_f2, eq 26', 0.0, 4.0),
    ParameterSpec('weight_bound', 10.0, 'Search bound |w_ij| (1/s); paper: 10', 0.0, 10.0,
                  low_exclusive=True),
    ParameterSpec('phase_bound', math.pi, 'Search bound |phi_ij| (rad); paper: pi', 0.0,
                  math.pi, low_exclusive=True),
    ParameterSpec('amplitude_bound', math.pi / 2,
                  'Search bound |R_i| (rad), also the servo range a wave may ask for; '
                  'paper: pi/2', 0.0, math.pi / 2, low_exclusive=True),
    ParameterSpec('servo_rate_limit_rad_s', _LIMITS.servo_rate_limit_rad_s,
                  'Fastest servo rate a wave may ask for (rad/s); the virtual fish slews 9.1',
                  0.0, 1000.0, low_exclusive=True),
    ParameterSpec('min_frequency_hz', _LIMITS.min_frequency_hz,
                  'Slowest tail beat a wave may ask for (Hz)', 0.0, 10.0, low_exclusive=True),
    ParameterSpec('max_rmse_deg', _LIMITS.max_rmse_deg,
                  'Largest swing-angle RMSE of a fit that may be used (deg); paper fit: 1.7',
                  0.0, 90.0, low_exclusive=True),
    ParameterSpec('alpha', 20.0, 'Convergence gain alpha given to fitted gaits (1/s)', 0.0,
                  200.0, low_exclusive=True),
    ParameterSpec('samples_per_period', 48, 'Quadrature points of the loss per period', 8,
                  2000),
    ParameterSpec('apply_timeout_s', 5.0, 'Wait for the CPG node to accept (s)', 0.1, 60.0),
    ParameterSpec('library_path', str(default_library_path()),
                  'Gait library file (YAML): read at start-up and when changed, every '
                  'successful fit stored; default $ROS_HOME/wirefish/gaits.yaml or '
                  '~/.ros/wirefish/gaits.yaml'),
) + geometry_parameters(BODY_WAVE_GEOMETRY_FIELDS), RULE)  # the fit needs the body wave's
