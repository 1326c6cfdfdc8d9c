# SPDX-License-Identifier: Apache-2.0
"""
The planner node's parameters as one table (no rclpy import).

The fish's geometry is the graph's one geometry block (``geometry_parameters``): eq 18 needs
it. Defaults are those of ``GaitLimits()``, ``YawGains()`` and ``WaveSpec()``. The rule of
their combination (``RULE``) is that ``planner_config.planner_from`` builds a planner of them;
validation and declaration are the shared ones of ``wirefish_common.parameter_table``.
"""

from __future__ import annotations

import math

from wirefish_common.parameter_table import builds, ParameterSpec, ParameterTable, Rule
from wirefish_cpg.gait_library import default_library_path
from wirefish_kinematics.geometry_parameters import geometry_parameters
from wirefish_kinematics.wave_spec import WaveSpec
from wirefish_planner.gait_choice import GaitLimits
from wirefish_planner.planner_config import planner_from
from wirefish_planner.yaw_control import YawGains

HALF_PI = math.pi / 2
_LIMITS, _GAINS, _WAVE = GaitLimits(), YawGains(), WaveSpec()
RULE: Rule = builds(planner_from)
TABLE = ParameterTable((
    ParameterSpec('cpg_node_name', 'cpg_node',
                  'Name (relative or absolute) of the CPG node the planner drives'),
    ParameterSpec('cmd_vel_timeout_s', 0.5,
                  'Rest (speed 0, hold released) after this long without cmd_vel (s)', 0.0,
                  60.0, low_exclusive=True),
    ParameterSpec('imu_timeout_s', 0.5,
                  'Turn open loop (feed-forward only) after this long without imu/data (s)',
                  0.0, 60.0, low_exclusive=True),
    ParameterSpec('control_rate_hz', 20.0, 'Rate of cpg_command and planner_state (Hz)', 1.0,
                  200.0),
    ParameterSpec('min_frequency_hz', _LIMITS.min_frequency_hz,
                  'Lowest tail-beat frequency of a gait (Hz)', 0.0, 10.0, low_exclusive=True),
    ParameterSpec('max_frequency_hz', _LIMITS.max_frequency_hz,
                  'Highest tail-beat frequency of a gait (Hz)', 0.0, 10.0, low_exclusive=True),
    ParameterSpec('max_amplitude_scale', _LIMITS.max_amplitude_scale,
                  "Largest factor on Table 1's R_i (1: tail tip ~8.8 cm)", 0.0, 3.3,
                  low_exclusive=True),
    ParameterSpec('servo_rate_limit_rad_s', _LIMITS.servo_rate_limit_rad_s,
                  "Servo slew limit (rad/s); the virtual fish's is 9.1", 0.0, 100.0,
                  low_exclusive=True),
    ParameterSpec('slew_margin', _LIMITS.slew_margin,
                  'Fraction of the slew limit a gait may use', 0.0, 1.0, low_exclusive=True),
    ParameterSpec('servo_limit_rad', _LIMITS.servo_limit_rad, 'Servo angle range (+-rad)', 0.0,
                  math.pi, low_exclusive=True),
    ParameterSpec('max_offset_rad', _LIMITS.max_offset_rad,
                  'Largest turning offset b (rad); output limit of the yaw PI', 0.0, HALF_PI,
                  low_exclusive=True),
    ParameterSpec('turn_gain', _GAINS.turn_gain,
                  'Feed-forward k of r = k U b (rad/s per rad of offset per m/s; < 0: a tail '
                  'held right turns right)', -100.0, 100.0),
    ParameterSpec('yaw_rate_kp', _GAINS.kp, 'Proportional gain of the yaw-rate PI (1)', 0.0,
                  20.0),
    ParameterSpec('yaw_rate_ki', _GAINS.ki, 'Integral gain of the yaw-rate PI (1/s)', 0.0,
                  20.0),
    ParameterSpec('yaw_rate_integral_limit', _GAINS.integral_limit,
                  'Anti-windup: largest yaw rate the integrator may add (rad/s)', 0.0, 5.0),
    ParameterSpec('heading_gain', _GAINS.heading_gain,
                  'Heading hold: yaw-rate reference per rad of heading error (1/s)', 0.0, 20.0),
    ParameterSpec('max_hold_rate', _GAINS.max_hold_rate,
                  'Heading hold: largest yaw-rate reference (rad/s)', 0.0, 5.0),
    ParameterSpec('heading_hold', True,
                  'angular.z = 0 holds the heading the turn ended on (else yaw rate 0)'),
    ParameterSpec('yaw_control', True,
                  'Close the yaw loops on imu/data (false: feed-forward offsets only)'),
    ParameterSpec('gait_source', 'table1',
                  "Gait family: 'table1' (Table 1 locked at f, R_i scaled) or 'library' (the "
                  "gait library's fits of the reference wave, blended inside their grid; Table "
                  '1 while the library has no such family)'),
    ParameterSpec('library_path', str(default_library_path()),
                  "Gait library file (tuner_node's library_path); read at start-up and on any "
                  'parameter change'),
    ParameterSpec('reference_wave_c1', _WAVE.c1,
                  "Library family's reference wave c1 (m/m), eq 23; scaled by s", -10.0, 10.0),
    ParameterSpec('reference_wave_c2', _WAVE.c2,
                  "Library family's reference wave c2 (1/m), eq 23; scaled by s", -100.0,
                  100.0),
    ParameterSpec('reference_wave_k', _WAVE.k, "Library family's reference wave k (rad/m)", 0.0,
                  100.0, low_exclusive=True),
    ParameterSpec('rest_at_start', True,
                  'Rest the CPG at start-up (no cmd_vel yet: the fish rests); false: leave '
                  'cpg_node as it is until the first cmd_vel'),
) + geometry_parameters(), RULE)  # eq 18 needs the fish's geometry: the graph's /** block
