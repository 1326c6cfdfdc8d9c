# SPDX-License-Identifier: Apache-2.0
"""
Pure conversions of telemetry to ROS conventions (REP-103, REP-145); no rclpy.

Attitude convention (documented in PROTOCOL.md and README.md): the board reports roll, pitch,
yaw (rad) as ZYX intrinsic Euler angles of ``imu_link`` relative to an ENU world frame, i.e.
R = Rz(yaw) Ry(pitch) Rx(roll): first yaw about the world's z (up, counter-clockwise
positive), then pitch about the new y (left), then roll about the new x (forward).
"""

from __future__ import annotations

import math


def quaternion_from_rpy(roll: float, pitch: float, yaw: float
                        ) -> tuple[float, float, float, float]:
    """Return (x, y, z, w) of R = Rz(yaw) Ry(pitch) Rx(roll) (ZYX intrinsic), unit norm."""
    cr, sr = math.cos(roll / 2.0), math.sin(roll / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def rpy_from_quaternion(x: float, y: float, z: float, w: float
                        ) -> tuple[float, float, float]:
    """Return (roll, pitch, yaw) of a unit quaternion, the inverse of ``quaternion_from_rpy``."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def diagonal_covariance(stddevs: tuple[float, float, float]) -> list[float]:
    """
    Return the row-major 3x3 covariance with the variances of ``stddevs`` on the diagonal.

    REP-145 / sensor_msgs/Imu: all zeros means "covariance unknown"; a standard deviation of 0
    therefore yields 0 (unknown), never a claim of perfect accuracy.
    """
    cov = [0.0] * 9
    for i, sigma in enumerate(stddevs):
        cov[4 * i] = float(sigma) ** 2
    return cov


NOT_PROVIDED = [-1.0] + [0.0] * 8  # sensor_msgs/Imu: element 0 = -1 when a field has no data
