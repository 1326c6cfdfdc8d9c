# SPDX-License-Identifier: Apache-2.0
"""
Serialized messages read in place (plain CDR): the few fields a hot intake needs, no message.

A raw subscription (rclpy ``raw=True``) or a batch intake (``batch_intake``) hands over the
bytes DDS carried. The servo intakes need a JointState's header stamp, joint names and position
and velocity arrays (``read_joint_state``: a ``JointStateView``, which ``servo_joints`` reads as
it reads a message; effort is skipped); the planner's yaw loop needs an Imu's stamp,
orientation, ``orientation_covariance[0]`` (-1: no orientation, REP-145) and angular velocity
(``read_imu``: an ``ImuView``). Both read with ``CdrReader``.

Layout (plain CDR, XCDR1, what rmw_fastrtps sends for ROS 2 types): a 4-byte encapsulation
header (``00 01``: little endian, ``00 00``: big endian; two option bytes), then the fields in
order, each aligned to its own size counted from the end of that header. A string is a uint32
length that counts its NUL terminator, then its bytes; a sequence is a uint32 count, then its
elements; a fixed array is its elements alone. Bytes that do not hold the whole message raise
``CdrError`` (a ValueError) naming what is wrong; nothing is read past the end.
"""

from __future__ import annotations

import struct
from typing import NamedTuple

HEADER_SIZE = 4
_BYTE_ORDER = {b'\x00\x01': '<', b'\x00\x00': '>'}
# No name or frame id of this graph is longer; a longer one is corruption, not a name.
MAX_NAME_BYTES = 256


class CdrError(ValueError):
    """Serialized bytes that are not a whole message of the type read."""


class CdrReader:
    """Reads aligned CDR primitives of a ``type_name`` message from ``data``, in order."""

    def __init__(self, data: bytes, type_name: str) -> None:
        """Check the encapsulation header; the next read starts after it."""
        order = _BYTE_ORDER.get(bytes(data[:2]))
        if order is None or len(data) < HEADER_SIZE:
            raise CdrError(f'not a CDR encapsulation: {bytes(data[:4]).hex() or "no bytes"}')
        self.data, self.offset, self.type_name = data, HEADER_SIZE, type_name
        self._u32 = struct.Struct(order + 'I')
        self._stamp = struct.Struct(order + 'iI')
        self._order = order

    def _take(self, size: int, align: int, what: str) -> int:
        start = self.offset + (-(self.offset - HEADER_SIZE) % align)
        if start + size > len(self.data):
            raise CdrError(f'{self.type_name} bytes end inside {what} (offset {start}, '
                           f'{size} bytes, {len(self.data)} in all)')
        self.offset = start + size
        return start

    def stamp(self) -> tuple[int, int]:
        """Read a builtin_interfaces/Time: seconds and nanoseconds."""
        return self._stamp.unpack_from(self.data, self._take(8, 4, 'header.stamp'))

    def count(self, what: str) -> int:
        """Read a uint32: a sequence's count or a string's length."""
        count: int = self._u32.unpack_from(self.data, self._take(4, 4, what))[0]
        return count

    def string(self, what: str) -> str:
        """Read a UTF-8 string: NUL-terminated, at most ``MAX_NAME_BYTES`` long."""
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
        """Read a sequence of float64."""
        count = self.count(what)
        if count * 8 > len(self.data):
            raise CdrError(f'{what} claims {count} values in {len(self.data)} bytes')
        return self.fixed_doubles(count, what)

    def fixed_doubles(self, count: int, what: str) -> tuple[float, ...]:
        """Read ``count`` float64 of a fixed-size array or a nested message's fields."""
        if count == 0:
            return ()
        start = self._take(8 * count, 8, what)
        return struct.unpack_from(f'{self._order}{count}d', self.data, start)


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
