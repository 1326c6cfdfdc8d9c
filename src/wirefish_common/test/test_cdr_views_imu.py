# SPDX-License-Identifier: Apache-2.0
"""The Imu CDR reader against rclpy's own serialization, and on bytes that are not one."""

import numpy as np
import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import Imu
from wirefish_common.cdr_views import CdrError, read_imu


def _random_message(rng: np.random.Generator) -> Imu:
    msg = Imu()
    msg.header.stamp.sec = int(rng.integers(-2 ** 31, 2 ** 31))
    msg.header.stamp.nanosec = int(rng.integers(0, 10 ** 9))
    msg.header.frame_id = ''.join(rng.choice(list('abc_xyz019'), int(rng.integers(0, 20))))
    x, y, z, w = rng.normal(size=4)
    msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = x, y, z, w
    msg.orientation_covariance = rng.normal(size=9).tolist()
    wx, wy, wz = rng.normal(size=3)
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = wx, wy, wz
    msg.angular_velocity_covariance = rng.normal(size=9).tolist()
    msg.linear_acceleration.z = float(rng.normal())
    return msg


@pytest.mark.parametrize('seed', range(40))
def test_the_reader_reads_what_rclpy_serialized(seed):
    msg = _random_message(np.random.default_rng(seed))
    view = read_imu(serialize_message(msg))
    q, v = msg.orientation, msg.angular_velocity
    assert (view.sec, view.nanosec) == (msg.header.stamp.sec, msg.header.stamp.nanosec)
    assert view.frame_id == msg.header.frame_id
    assert view.orientation == (q.x, q.y, q.z, q.w)
    assert view.orientation_covariance_0 == msg.orientation_covariance[0]
    assert view.angular_velocity == (v.x, v.y, v.z)


def test_no_orientation_reads_as_rep_145_says():
    msg = Imu()
    msg.orientation_covariance[0] = -1.0
    assert read_imu(serialize_message(msg)).orientation_covariance_0 == -1.0


def test_bytes_cut_before_the_angular_velocity_ends_raise_cdr_error():
    data = serialize_message(_random_message(np.random.default_rng(0)))
    needed = len(data) - 8 * (9 + 3 + 9)  # what follows angular_velocity is not read
    read_imu(data[:needed])
    for size in range(needed):
        with pytest.raises(CdrError):
            read_imu(data[:size])


@pytest.mark.parametrize('data', [b'', b'\x02\x01\x00\x00' + bytes(400), b'\x00\x01\x00\x00'
                                  + b'\x00\x00\x00\x00' * 2 + b'\xff\xff\xff\x7f'])
def test_what_is_no_imu_raises_cdr_error(data):
    with pytest.raises(CdrError):
        read_imu(data)
