"""
Parameters of bridge_node: one table and the rules of their combination.

Name, default, description and range of each; no rclpy, so the validation is testable without
ROS.
"""

from __future__ import annotations

from collections.abc import Mapping
import math
from typing import Any

from wirefish_bridge.protocol import DEFAULT_BAUDRATE
from wirefish_common.parameter_table import ParameterSpec

PARAMETERS = (
    ParameterSpec('port', '/dev/ttyUSB0', 'Serial device of the fish (a stable path such as '
                  '/dev/serial/by-id/... or the virtual fish symlink); reopened when it returns'),
    ParameterSpec('baudrate', DEFAULT_BAUDRATE, 'Serial baud rate', 1200, 4000000),
    ParameterSpec('max_command_rate_hz', 100.0, 'Most servo command frames sent per second',
                  1.0, 1000.0),
    ParameterSpec('command_timeout_s', 0.5,
                  'servo_cmd silence after which the bridge commands neutral (s)', 0.02, 10.0),
    ParameterSpec('servo_limit_rad', math.pi / 2, 'Commands are clamped to +-this (rad)',
                  0.0, math.pi),
    ParameterSpec('heartbeat_rate_hz', 5.0, 'Rate of the host heartbeat (Hz)', 0.5, 50.0),
    ParameterSpec('heartbeat_timeout_s', 1.0,
                  'Fish heartbeat age above which the link is reported stale (s)', 0.1, 10.0),
    ParameterSpec('fish_identify_timeout_s', 2.0,
                  'After opening the port the bridge writes nothing until the device sends a '
                  'fish HEARTBEAT (2 Hz); a device silent this long is closed and reopened (s)',
                  0.2, 30.0),
    ParameterSpec('reconnect_backoff_min_s', 0.1, 'First retry delay after a lost port (s)',
                  0.01, 5.0),
    ParameterSpec('reconnect_backoff_max_s', 1.0, 'Longest retry delay (s); doubles up to it',
                  0.01, 30.0),
    ParameterSpec('diagnostics_rate_hz', 1.0, 'Rate of /diagnostics (Hz)', 0.1, 10.0),
    ParameterSpec('battery_rate_hz', 10.0,
                  'Rate of battery (Hz), at most the telemetry rate; a change of the low-battery '
                  'flag is published at once', 0.1, 1000.0),
    ParameterSpec('imu_frame_id', 'imu_link', 'frame_id of imu/data and attitude'),
    ParameterSpec('orientation_stddev_rad', 0.0175,
                  'Roll and pitch standard deviation (rad) for the covariance; 0 = unknown',
                  0.0, math.pi),
    ParameterSpec('yaw_stddev_rad', 0.1,
                  'Yaw standard deviation (rad); no magnetometer, yaw drifts; 0 = unknown',
                  0.0, math.pi),
    ParameterSpec('angular_velocity_stddev_rad_s', 0.005,
                  'Gyro standard deviation (rad/s); 0 = unknown', 0.0, 10.0),
    ParameterSpec('linear_acceleration_stddev_m_s2', 0.05,
                  'Accelerometer standard deviation (m/s^2); 0 = unknown', 0.0, 100.0),
)
SPECS = {spec.name: spec for spec in PARAMETERS}
LINK_PARAMETERS = {'port', 'baudrate', 'reconnect_backoff_min_s', 'reconnect_backoff_max_s',
                   'fish_identify_timeout_s'}


def check_combination(values: Mapping[str, Any]) -> str | None:
    """Return why a full set of parameter values is inconsistent, or None."""
    if values['reconnect_backoff_max_s'] < values['reconnect_backoff_min_s']:
        return 'reconnect_backoff_max_s must be >= reconnect_backoff_min_s'
    # An all-zero covariance means "unknown"; one zero beside non-zero ones would claim that
    # angle perfectly known.
    if (values['orientation_stddev_rad'] == 0.0) != (values['yaw_stddev_rad'] == 0.0):
        return ('orientation_stddev_rad and yaw_stddev_rad must both be > 0, or both 0 '
                '(orientation covariance unknown)')
    return None
