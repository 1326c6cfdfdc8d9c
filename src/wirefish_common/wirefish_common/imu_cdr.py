"""
sensor_msgs/Imu read from its serialized bytes (CDR): what a yaw loop needs of it.

The planner takes imu/data in batches at its control tick (``batch_intake``): each sample's
header stamp, orientation, ``orientation_covariance[0]`` (-1 when there is no orientation,
REP-145) and angular velocity, read in place without building a Python message. The linear
acceleration and the other covariances are not read. Bytes that do not hold them raise
``CdrError`` (``cdr_reader``).
"""

from __future__ import annotations

from typing import NamedTuple

from wirefish_common.cdr_reader import CdrError, CdrReader

__all__ = ['CdrError', 'ImuView', 'read_imu']

COVARIANCE_SIZE = 9  # float64[9], row major about x, y, z


class ImuView(NamedTuple):
    """The fields of a serialized Imu a yaw loop reads."""

    sec: int
    nanosec: int
    frame_id: str
    orientation: tuple[float, float, float, float]  # x, y, z, w
    orientation_covariance_0: float
    angular_velocity: tuple[float, float, float]  # x, y, z (rad/s)


def read_imu(data: bytes) -> ImuView:
    """Return the stamp, frame id, orientation, its first covariance and the angular velocity."""
    reader = CdrReader(data, 'Imu')
    sec, nanosec = reader.stamp()
    frame_id = reader.string('header.frame_id')
    x, y, z, w = reader.fixed_doubles(4, 'orientation')
    covariance = reader.fixed_doubles(COVARIANCE_SIZE, 'orientation_covariance')
    wx, wy, wz = reader.fixed_doubles(3, 'angular_velocity')
    return ImuView(sec, nanosec, frame_id, (x, y, z, w), covariance[0], (wx, wy, wz))
