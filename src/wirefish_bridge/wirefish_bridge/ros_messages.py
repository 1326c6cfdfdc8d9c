"""
ROS messages of the bridge built from protocol messages (message types only, no rclpy).

Conventions: REP-103 (SI, FLU body axes) and REP-145 (IMU data in the sensor frame, orientation
relative to ENU); see ``conversions`` for the roll/pitch/yaw -> quaternion convention.
"""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import BatteryState, Imu, JointState

from wirefish_bridge.conversions import diagonal_covariance, NOT_PROVIDED, quaternion_from_rpy
from wirefish_bridge.protocol import Status, Telemetry
from wirefish_common.servo_joints import servo_joint_state


def imu_message(telemetry: Telemetry, stamp: Time, frame_id: str,
                orientation_stddev: tuple[float, float, float], gyro_stddev: float,
                accel_stddev: float) -> Imu:
    """
    Return the sensor_msgs/Imu of ``telemetry`` (orientation, rates, specific force).

    When the board flags IMU_FAULT the values are passed on but every covariance says "no
    data" (element 0 = -1), so a filter that fuses imu/data ignores them.
    """
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


def attitude_message(telemetry: Telemetry, stamp: Time, frame_id: str) -> Vector3Stamped:
    """Return roll, pitch, yaw (rad) as x, y, z of a geometry_msgs/Vector3Stamped."""
    msg = Vector3Stamped()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.vector.x, msg.vector.y, msg.vector.z = telemetry.roll, telemetry.pitch, telemetry.yaw
    return msg


def servo_state_message(telemetry: Telemetry, stamp: Time) -> JointState:
    """Return the measured servo angles (rad) as a sensor_msgs/JointState (no velocity)."""
    return servo_joint_state((telemetry.servo_1, telemetry.servo_2), stamp=stamp)


def battery_message(telemetry: Telemetry, stamp: Time, low_battery: bool,
                    frame_id: str = 'base_link') -> BatteryState:
    """Return a sensor_msgs/BatteryState with the voltage; unmeasured fields are NaN."""
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
