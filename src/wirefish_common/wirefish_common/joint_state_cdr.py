"""
sensor_msgs/JointState read from its serialized bytes (CDR), without building the message.

A raw subscription (rclpy ``raw=True``) hands its callback the bytes DDS carried; the servo
intakes need the header stamp, the joint names and the position and velocity arrays of a
two-joint message, not a Python message with its array.array fields. ``read_joint_state``
returns them as a ``JointStateView``, which ``servo_joints.servo_angles`` and ``servo_sample``
read as they read a message (effort is skipped).

Layout (plain CDR, XCDR1, what rmw_fastrtps sends for ROS 2 types): a 4-byte encapsulation
header (``00 01``: little endian, ``00 00``: big endian; two option bytes), then the fields in
order, each aligned to its own size counted from the end of that header. A string is a uint32
length that counts its NUL terminator, then its bytes; a sequence is a uint32 count, then its
elements. Bytes that do not hold a whole JointState raise ``CdrError`` (a ValueError) naming
what is wrong; nothing is read past the end.
"""

from __future__ import annotations

import struct
from typing import NamedTuple

HEADER_SIZE = 4
_BYTE_ORDER = {b'\x00\x01': '<', b'\x00\x00': '>'}
# No joint of this graph has a longer name; a longer one is corruption, not a joint.
MAX_NAME_BYTES = 256


class CdrError(ValueError):
    """Serialized bytes that are not a whole sensor_msgs/JointState."""


class JointStateView(NamedTuple):
    """The fields of a serialized JointState the servo intakes read (stamp, names, arrays)."""

    sec: int
    nanosec: int
    frame_id: str
    name: tuple[str, ...]
    position: tuple[float, ...]
    velocity: tuple[float, ...]


class _Reader:
    """Reads aligned CDR primitives from ``data`` after its encapsulation header."""

    def __init__(self, data: bytes, order: str) -> None:
        self.data, self.offset = data, HEADER_SIZE
        self._u32 = struct.Struct(order + 'I')
        self._stamp = struct.Struct(order + 'iI')
        self._order = order

    def _take(self, size: int, align: int, what: str) -> int:
        start = self.offset + (-(self.offset - HEADER_SIZE) % align)
        if start + size > len(self.data):
            raise CdrError(f'JointState bytes end inside {what} (offset {start}, '
                           f'{size} bytes, {len(self.data)} in all)')
        self.offset = start + size
        return start

    def stamp(self) -> tuple[int, int]:
        return self._stamp.unpack_from(self.data, self._take(8, 4, 'header.stamp'))

    def count(self, what: str) -> int:
        return self._u32.unpack_from(self.data, self._take(4, 4, what))[0]

    def string(self, what: str) -> str:
        size = self.count(what)
        if not 1 <= size <= MAX_NAME_BYTES:
            raise CdrError(f'{what} has an absurd length {size}')
        start = self._take(size, 1, what)
        if self.data[start + size - 1] != 0:
            raise CdrError(f'{what} is not NUL-terminated')
        try:
            return self.data[start:start + size - 1].decode('utf-8')
        except UnicodeDecodeError as error:
            raise CdrError(f'{what} is not UTF-8') from error

    def doubles(self, what: str) -> tuple[float, ...]:
        count = self.count(what)
        if count * 8 > len(self.data):
            raise CdrError(f'{what} claims {count} values in {len(self.data)} bytes')
        if count == 0:
            return ()
        start = self._take(8 * count, 8, what)
        return struct.unpack_from(f'{self._order}{count}d', self.data, start)


def read_joint_state(data: bytes) -> JointStateView:
    """Return the stamp, frame id, names, positions and velocities of serialized ``data``."""
    order = _BYTE_ORDER.get(bytes(data[:2]))
    if order is None or len(data) < HEADER_SIZE:
        raise CdrError(f'not a CDR encapsulation: {bytes(data[:4]).hex() or "no bytes"}')
    reader = _Reader(data, order)
    sec, nanosec = reader.stamp()
    frame_id = reader.string('header.frame_id')
    names = reader.count('name')
    if names * 5 > len(data):  # every name takes at least its length and a NUL
        raise CdrError(f'name claims {names} joints in {len(data)} bytes')
    name = tuple(reader.string(f'name[{i}]') for i in range(names))
    position = reader.doubles('position')
    velocity = reader.doubles('velocity')
    return JointStateView(sec, nanosec, frame_id, name, position, velocity)
