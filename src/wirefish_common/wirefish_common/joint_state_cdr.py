"""
sensor_msgs/JointState read from its serialized bytes (CDR), without building the message.

A raw subscription (rclpy ``raw=True``) hands its callback the bytes DDS carried; the servo
intakes need the header stamp, the joint names and the position and velocity arrays of a
two-joint message, not a Python message with its array.array fields. ``read_joint_state``
returns them as a ``JointStateView``, which ``servo_joints.servo_angles`` and ``servo_sample``
read as they read a message (effort is skipped).

Bytes that do not hold a whole JointState raise ``CdrError`` (a ValueError, from
``cdr_reader``, which says the layout) naming what is wrong; nothing is read past the end.
"""

from __future__ import annotations

from typing import NamedTuple

from wirefish_common.cdr_reader import CdrError, CdrReader

__all__ = ['CdrError', 'JointStateView', 'read_joint_state']


class JointStateView(NamedTuple):
    """The fields of a serialized JointState the servo intakes read (stamp, names, arrays)."""

    sec: int
    nanosec: int
    frame_id: str
    name: tuple[str, ...]
    position: tuple[float, ...]
    velocity: tuple[float, ...]


def read_joint_state(data: bytes) -> JointStateView:
    """Return the stamp, frame id, names, positions and velocities of serialized ``data``."""
    reader = CdrReader(data, 'JointState')
    sec, nanosec = reader.stamp()
    frame_id = reader.string('header.frame_id')
    names = reader.count('name')
    if names * 5 > len(data):  # every name takes at least its length and a NUL
        raise CdrError(f'name claims {names} joints in {len(data)} bytes')
    name = tuple(reader.string(f'name[{i}]') for i in range(names))
    position = reader.doubles('position')
    velocity = reader.doubles('velocity')
    return JointStateView(sec, nanosec, frame_id, name, position, velocity)
