# SPDX-License-Identifier: Apache-2.0
"""The JointState CDR reader against rclpy's own serialization, and on bytes that are not one."""

import numpy as np
import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from wirefish_common.cdr_views import CdrError, read_joint_state
from wirefish_common.servo_joints import servo_sample


def _random_message(rng: np.random.Generator) -> JointState:
    joints = int(rng.integers(0, 6))
    letters = np.array(list('abcdefghijklmnopqrstuvwxyz_0123456789'))

    def word(most: int) -> str:
        return ''.join(rng.choice(letters, int(rng.integers(0, most))))
    msg = JointState()
    msg.header.stamp.sec = int(rng.integers(-2 ** 31, 2 ** 31))
    msg.header.stamp.nanosec = int(rng.integers(0, 10 ** 9))
    msg.header.frame_id = word(12)
    msg.name = [word(15) for _ in range(joints)]
    msg.position = rng.normal(size=joints).tolist()
    # velocity and effort: empty, one per joint, or another length (the type allows it)
    msg.velocity = rng.normal(size=int(rng.choice([0, joints, 3]))).tolist()
    msg.effort = rng.normal(size=int(rng.choice([0, joints]))).tolist()
    return msg


@pytest.mark.parametrize('seed', range(60))
def test_the_reader_reads_what_rclpy_serialized(seed):
    msg = _random_message(np.random.default_rng(seed))
    view = read_joint_state(serialize_message(msg))
    assert (view.sec, view.nanosec) == (msg.header.stamp.sec, msg.header.stamp.nanosec)
    assert view.frame_id == msg.header.frame_id
    assert view.name == tuple(msg.name)
    assert view.position == tuple(msg.position)
    assert view.velocity == tuple(msg.velocity)


def test_the_servo_joints_read_a_view_as_they_read_the_message():
    msg = JointState(name=['other', 'servo_2', 'servo_1'], position=[9.0, 0.2, -0.1],
                     velocity=[0.0, 1.5, -2.5])
    assert servo_sample(read_joint_state(serialize_message(msg))) == servo_sample(msg)


def test_every_truncation_of_a_message_raises_cdr_error():
    data = serialize_message(JointState(name=['servo_1', 'servo_2'], position=[0.1, 0.2],
                                        velocity=[1.0, 2.0]))
    whole = read_joint_state(data)
    for size in range(len(data)):
        try:
            view = read_joint_state(data[:size])
        except CdrError:
            continue
        # Only the padding after velocity may go: what it read is then the whole message.
        assert view == whole and size >= len(data) - 8


@pytest.mark.parametrize('seed', range(20))
def test_corrupted_bytes_raise_cdr_error_or_read_within_the_bytes(seed):
    rng = np.random.default_rng(seed)
    data = np.frombuffer(serialize_message(_random_message(rng)), dtype=np.uint8)
    for _ in range(200):
        corrupted = data.copy()
        at = rng.integers(0, len(corrupted), int(rng.integers(1, 4)))
        corrupted[at] = rng.integers(0, 256, at.size)
        try:
            view = read_joint_state(corrupted.tobytes())
        except CdrError:
            continue
        assert len(view.position) * 8 <= len(corrupted)


@pytest.mark.parametrize('data', [b'', b'\x00', b'\x07\x01\x00\x00' + bytes(40)])
def test_bytes_without_a_cdr_header_raise_cdr_error(data):
    with pytest.raises(CdrError, match='encapsulation'):
        read_joint_state(data)


def test_a_big_endian_message_reads_as_well():
    little = serialize_message(JointState(name=['servo_1'], position=[0.5]))
    big = (b'\x00\x00\x00\x00' + (7).to_bytes(4, 'big') + (0).to_bytes(4, 'big')
           + (1).to_bytes(4, 'big') + b'\x00' + bytes(3) + (1).to_bytes(4, 'big')
           + (8).to_bytes(4, 'big') + b'servo_1\x00' + (1).to_bytes(4, 'big') + bytes(4)
           + np.array([0.5], dtype='>f8').tobytes() + bytes(8))
    assert read_joint_state(big)[3:5] == read_joint_state(little)[3:5] == (('servo_1',), (0.5,))
    assert read_joint_state(big).sec == 7
