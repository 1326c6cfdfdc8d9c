# SPDX-License-Identifier: Apache-2.0
"""
Parameters of bridge_node: one table (``TABLE``) and the rule of their combination (``RULE``).

Name, default, description and range of each; no rclpy, so the validation is testable without
ROS.
"""

from __future__ import annotations

from collections.abc import Mapping
import enum
import math
from typing import Any

from wirefish_bridge.protocol import (COAST_RANGE_MS, DEFAULT_BAUDRATE, HEALTH_PERIOD_RANGE_MS,
                                      LINK_TIMEOUT_RANGE_MS, LinkConfig,
                                      TELEMETRY_PERIOD_RANGE_MS, TelemetryForm)
from wirefish_common.parameter_table import ParameterSpec, ParameterTable, Rule


class DriveMode(enum.StrEnum):
    """
    How the bridge drives the board (``drive_mode``).

    STREAM: the CPG node's servo_cmd is forwarded as SERVO_CMD at its rate (up to
    ``max_command_rate_hz``): for a wired link, or a computer on the fish wired to the board.
    GAIT: the CPG node's parameters (cpg_params) go out as GAIT messages and the board
    integrates eq 1 itself: for a radio on the board (the paper's build), whose link carries
    neither the 100 Hz commands nor a gap without a step.
    """

    STREAM = 'stream'
    GAIT = 'gait'


class TelemetryFormName(enum.StrEnum):
    """``telemetry_form``: the fish's telemetry message (LINK_CONFIG)."""

    FULL = 'full'         # TELEMETRY, 62 bytes on the wire
    COMPACT = 'compact'   # TELEMETRY_COMPACT, 38 bytes on the wire: for narrow radios


_SPECS = (
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
    ParameterSpec('drive_mode', DriveMode.STREAM.value,
                  'stream: forward servo_cmd as SERVO_CMD (a wired link, or a computer on the '
                  'fish); gait: send cpg_params as GAIT, the board integrates eq 1 (a radio '
                  'on the board)'),
    ParameterSpec('telemetry_period_s', 0.01,
                  "The fish's telemetry period (LINK_CONFIG; s, whole ms)",
                  TELEMETRY_PERIOD_RANGE_MS[0] / 1000.0, TELEMETRY_PERIOD_RANGE_MS[1] / 1000.0),
    ParameterSpec('telemetry_form', TelemetryFormName.FULL.value,
                  "The fish's telemetry message: full (TELEMETRY) or compact "
                  '(TELEMETRY_COMPACT, for narrow radios)'),
    ParameterSpec('health_period_s', 2.0,
                  "Period of the fish's HEALTH report (LINK_CONFIG; s; 0 = none)",
                  0.0, HEALTH_PERIOD_RANGE_MS[1] / 1000.0),
    ParameterSpec('link_timeout_s', 1.5,
                  'Gait mode: no valid host frame this long and the fish coasts (LINK_CONFIG; s)',
                  LINK_TIMEOUT_RANGE_MS[0] / 1000.0, LINK_TIMEOUT_RANGE_MS[1] / 1000.0),
    ParameterSpec('coast_s', 3.0,
                  'Gait mode: how long the fish swims its gait on after the link timeout, '
                  'then comes to rest through the oscillator (LINK_CONFIG; s)',
                  COAST_RANGE_MS[0] / 1000.0, COAST_RANGE_MS[1] / 1000.0),
    ParameterSpec('gait_resend_s', 0.4,
                  'Gait mode: an unacknowledged GAIT or LINK_CONFIG is sent again this often (s)',
                  0.05, 10.0),
    ParameterSpec('gait_repeat_s', 0.15,
                  'Gait mode: a new GAIT goes a second time this long after its first copy '
                  'unless acknowledged by then, so that one lost copy or ACK on a lossy radio '
                  'costs no resend wait; 0 sends one copy (s)', 0.0, 10.0),
    ParameterSpec('gait_min_interval_s', 0.1,
                  'Gait mode: a new GAIT goes out no sooner than this after the last one; '
                  'changes in between are coalesced, the newest goes (s)', 0.0, 10.0),
    ParameterSpec('divergence_bound_rad', 0.1,
                  "Gait mode: the board's servo_state may differ from servo_cmd by this much in "
                  'offset + amplitude over divergence_window_s before /diagnostics warns (rad)',
                  0.0, math.pi, low_exclusive=True),
    ParameterSpec('divergence_window_s', 3.0,
                  'Gait mode: the window of the divergence check (s, a few periods)', 0.5, 60.0),
)
LINK_PARAMETERS = {'port', 'baudrate', 'reconnect_backoff_min_s', 'reconnect_backoff_max_s',
                   'fish_identify_timeout_s'}
LINK_CONFIG_PARAMETERS = {'telemetry_period_s', 'telemetry_form', 'health_period_s',
                          'link_timeout_s', 'coast_s'}


def link_config(values: Mapping[str, Any]) -> LinkConfig:
    """Return the LINK_CONFIG of the parameters (times in whole ms)."""
    return LinkConfig(round(values['telemetry_period_s'] * 1000.0),
                      TelemetryForm[TelemetryFormName(values['telemetry_form']).name],
                      round(values['health_period_s'] * 1000.0),
                      round(values['link_timeout_s'] * 1000.0), round(values['coast_s'] * 1000.0))


def _combination_problem(values: Mapping[str, Any]) -> str | None:
    """Return why a full set of parameter values is inconsistent, or None."""
    if values['reconnect_backoff_max_s'] < values['reconnect_backoff_min_s']:
        return 'reconnect_backoff_max_s must be >= reconnect_backoff_min_s'
    # An all-zero covariance means "unknown"; one zero beside non-zero ones would claim that
    # angle perfectly known.
    if (values['orientation_stddev_rad'] == 0.0) != (values['yaw_stddev_rad'] == 0.0):
        return ('orientation_stddev_rad and yaw_stddev_rad must both be > 0, or both 0 '
                '(orientation covariance unknown)')
    for name, kind in (('drive_mode', DriveMode), ('telemetry_form', TelemetryFormName)):
        if values[name] not in {member.value for member in kind}:
            return (f'{name} must be one of {", ".join(member.value for member in kind)}, '
                    f'got {values[name]!r}')
    return link_config(values).problem()


RULE: Rule = _combination_problem
TABLE = ParameterTable(_SPECS, RULE)
