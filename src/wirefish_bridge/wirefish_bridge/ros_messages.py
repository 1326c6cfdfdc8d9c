# SPDX-License-Identifier: Apache-2.0
"""
ROS messages of the bridge built from protocol messages (message types only, no rclpy).

Conventions: REP-103 (SI, FLU body axes) and REP-145 (IMU data in the sensor frame, orientation
relative to ENU); see ``conversions`` for the roll/pitch/yaw -> quaternion convention. Each
telemetry message may be either form (TELEMETRY or TELEMETRY_COMPACT): a compact one gives the
same ROS messages, its values to the compact form's precision.
"""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import BatteryState, Imu, JointState

from wirefish_bridge.conversions import diagonal_covariance, NOT_PROVIDED, quaternion_from_rpy
from wirefish_bridge.protocol import (ClockSource, Health, HealthFlags, ResetCause, Status,
                                      Telemetry, TelemetryCompact)
from wirefish_common.servo_joints import servo_joint_state

AnyTelemetry = Telemetry | TelemetryCompact


def _full(telemetry: AnyTelemetry) -> Telemetry:
    return telemetry.expanded() if isinstance(telemetry, TelemetryCompact) else telemetry


def imu_message(telemetry: AnyTelemetry, stamp: Time, frame_id: str,
                orientation_stddev: tuple[float, float, float], gyro_stddev: float,
                accel_stddev: float) -> Imu:
    """
    Return the sensor_msgs/Imu of ``telemetry`` (orientation, rates, specific force).

    When the board flags IMU_FAULT the values are passed on but every covariance says "no
    data" (element 0 = -1), so a filter that fuses imu/data ignores them.
    """
    telemetry = _full(telemetry)
    msg = Imu()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    x, y, z, w = quaternion_from_rpy(telemetry.roll, telemetry.pitch, telemetry.yaw)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = x, y, z, w
    msg.orientation_covariance = diagonal_covariance(orientation_stddev)
    gx, gy, gz = telemetry.gyro
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gx, gy, gz
    msg.angular_velocity_covariance = diagonal_covariance((gyro_stddev,) * 3)
    ax, ay, az = telemetry.accel
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
    msg.linear_acceleration_covariance = diagonal_covariance((accel_stddev,) * 3)
    if telemetry.status & Status.IMU_FAULT:
        msg.orientation_covariance = list(NOT_PROVIDED)
        msg.angular_velocity_covariance = list(NOT_PROVIDED)
        msg.linear_acceleration_covariance = list(NOT_PROVIDED)
    return msg


def attitude_message(telemetry: AnyTelemetry, stamp: Time, frame_id: str) -> Vector3Stamped:
    """Return roll, pitch, yaw (rad) as x, y, z of a geometry_msgs/Vector3Stamped."""
    telemetry = _full(telemetry)
    msg = Vector3Stamped()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.vector.x, msg.vector.y, msg.vector.z = telemetry.roll, telemetry.pitch, telemetry.yaw
    return msg


def servo_state_message(telemetry: AnyTelemetry, stamp: Time) -> JointState:
    """Return the measured servo angles (rad) as a sensor_msgs/JointState (no velocity)."""
    telemetry = _full(telemetry)
    return servo_joint_state((telemetry.servo_1, telemetry.servo_2), stamp=stamp)


def battery_message(telemetry: AnyTelemetry, stamp: Time, low_battery: bool,
                    frame_id: str = 'base_link') -> BatteryState:
    """Return a sensor_msgs/BatteryState with the voltage; unmeasured fields are NaN."""
    telemetry = _full(telemetry)
    msg = BatteryState()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.voltage = telemetry.battery_v
    nan = math.nan
    msg.temperature = msg.current = msg.charge = msg.capacity = nan
    msg.design_capacity = msg.percentage = nan
    msg.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_UNKNOWN
    msg.power_supply_health = (BatteryState.POWER_SUPPLY_HEALTH_DEAD if low_battery
                               else BatteryState.POWER_SUPPLY_HEALTH_UNKNOWN)
    msg.power_supply_technology = BatteryState.POWER_SUPPLY_TECHNOLOGY_UNKNOWN
    msg.present = True
    msg.location = 'control cabin'
    return msg


def diagnostic_status(name: str, hardware_id: str, level: int, message: str,
                      values: dict[str, object]) -> DiagnosticStatus:
    """Return a diagnostic_msgs/DiagnosticStatus (level 0 OK, 1 WARN, 2 ERROR), values as text."""
    status = DiagnosticStatus(name=name, hardware_id=hardware_id, level=bytes([int(level)]),
                              message=message)
    status.values = [KeyValue(key=k, value=f'{v:.3f}' if isinstance(v, float) else str(v))
                     for k, v in values.items()]
    return status


# Resets that say something went wrong on the board (WARN); the rest are ordinary starts.
ALARMING_RESETS = frozenset({ResetCause.BROWN_OUT, ResetCause.IWDG, ResetCause.WWDG,
                             ResetCause.FAULT, ResetCause.LOW_POWER})


def _name(enum_type: type, value: int) -> str:
    try:
        return enum_type(value).name
    except ValueError:
        return f'unknown ({value})'


def health_values(health: Health) -> dict[str, object]:
    """Return a HEALTH report as /diagnostics key-values (names for the enums and flags)."""
    flags = [str(flag.name) for flag in HealthFlags if flag and health.flags & flag]
    values: dict[str, object] = {
        'reset_cause': _name(ResetCause, health.reset_cause),
        'clock_source': _name(ClockSource, health.clock_source),
        'health_flags': ', '.join(flags) or 'none',
        'board_uptime_s': health.uptime_ms / 1000.0,
        'stack_free_min_bytes': f'{health.stack_free_min} of {health.stack_size}',
    }
    if health.flags & HealthFlags.FAULT_RECORD:
        for name in ('fault_pc', 'fault_lr', 'fault_cfsr', 'fault_hfsr'):
            values[name] = f'0x{getattr(health, name):08x}'
    for name in ('uart_rx_overruns', 'tx_bytes_dropped', 'rx_crc', 'rx_frame',
                 'rx_unknown_type', 'rx_length', 'rx_invalid', 'imu_faults', 'imu_recoveries',
                 'i2c_bus_recoveries'):
        values[f'board_{name}'] = getattr(health, name)
    return values


def health_level(health: Health) -> tuple[int, str]:
    """Return the diagnostic level (0 OK, 1 WARN) of a HEALTH report and why."""
    reasons = []
    if health.reset_cause in ALARMING_RESETS:
        where = (f' at PC 0x{health.fault_pc:08x}'
                 if health.flags & HealthFlags.FAULT_RECORD else '')
        reasons.append(f'board reset by {_name(ResetCause, health.reset_cause)}{where}')
    if health.clock_source in (ClockSource.HSI_PLL, ClockSource.HSI):
        reasons.append(f'board clock on {_name(ClockSource, health.clock_source)} (crystal '
                       'failed)')
    if health.stack_size and health.stack_free_min == 0:
        reasons.append('board stack used to its end')
    return (1, '; '.join(reasons)) if reasons else (0, 'board healthy')
