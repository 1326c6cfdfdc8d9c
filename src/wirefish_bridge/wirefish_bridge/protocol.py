"""
Messages of the wirefish serial protocol (see PROTOCOL.md) and their payload layouts.

Pure data: no I/O, no rclpy. A frame body is ``type (u8) | seq (u16 LE) | payload | crc16 (u16
LE)``; this module packs and unpacks the payloads, ``codec`` does framing, CRC and streaming.
All multi-byte fields are little-endian; angles in rad, rates in rad/s, accelerations in m/s^2,
voltages in V, times in ms of the sender's clock.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import math
import struct

PROTOCOL_VERSION = 1
DEFAULT_BAUDRATE = 115200


class MsgType(enum.IntEnum):
    """The message type byte."""

    HEARTBEAT = 0x01
    SERVO_CMD = 0x10
    TELEMETRY = 0x20
    ERROR = 0x7F


class Role(enum.IntEnum):
    """Who sends a heartbeat."""

    HOST = 0
    FISH = 1


class ErrorCode(enum.IntEnum):
    """Codes of an ERROR message (sent by the fish about a frame it received)."""

    BAD_CRC = 1
    BAD_FRAME = 2
    UNKNOWN_TYPE = 3
    BAD_LENGTH = 4
    VERSION_MISMATCH = 5
    COMMAND_OUT_OF_RANGE = 6


class Status(enum.IntFlag):
    """Status flags of a TELEMETRY message (u16)."""

    NONE = 0
    FAILSAFE_COMMAND = 0x0001   # no SERVO_CMD for the fish's command timeout: servos neutral
    FAILSAFE_HEARTBEAT = 0x0002  # no host HEARTBEAT for the fish's heartbeat timeout: neutral
    SERVO_CLAMPED = 0x0004      # a commanded angle was beyond the mechanical limit
    LOW_BATTERY = 0x0008
    IMU_FAULT = 0x0010
    VERSION_MISMATCH = 0x0020   # the host's heartbeat announced another protocol version


@dataclass(frozen=True)
class Heartbeat:
    """Both ways, a few Hz: protocol version, sender role, sender uptime (ms, wraps)."""

    version: int = PROTOCOL_VERSION
    role: Role = Role.HOST
    uptime_ms: int = 0


@dataclass(frozen=True)
class ServoCommand:
    """Host -> fish: target angles of servo 1 and 2 (rad, reel angle phi_D,i of eq 2)."""

    servo_1: float
    servo_2: float


@dataclass(frozen=True)
class Telemetry:
    """
    Fish -> host, 100 Hz: board time, attitude, IMU, measured servos, battery, status.

    ``roll``/``pitch``/``yaw`` (rad): ZYX intrinsic Euler angles of the IMU frame relative to
    the world frame (ENU, z up; yaw about z, counter-clockwise positive). ``gyro`` (rad/s) and
    ``accel`` (m/s^2, specific force: +9.81 on z at rest) are (x, y, z) in the IMU frame (FLU).
    """

    board_time_ms: int
    roll: float
    pitch: float
    yaw: float
    gyro: tuple[float, float, float]
    accel: tuple[float, float, float]
    servo_1: float
    servo_2: float
    battery_v: float
    status: int = 0


@dataclass(frozen=True)
class ErrorReport:
    """Fish -> host: ``code`` (ErrorCode) about the received frame with sequence ``ref_seq``."""

    code: int
    ref_seq: int = 0


Message = Heartbeat | ServoCommand | Telemetry | ErrorReport

_HEARTBEAT = struct.Struct('<BBI')
_SERVO_CMD = struct.Struct('<ff')
_TELEMETRY = struct.Struct('<I' + 'f' * 12 + 'H')
_ERROR = struct.Struct('<BH')

PAYLOAD_SIZES = {
    MsgType.HEARTBEAT: _HEARTBEAT.size,
    MsgType.SERVO_CMD: _SERVO_CMD.size,
    MsgType.TELEMETRY: _TELEMETRY.size,
    MsgType.ERROR: _ERROR.size,
}


def message_type(message: Message) -> MsgType:
    """Return the type byte of ``message``."""
    if isinstance(message, Heartbeat):
        return MsgType.HEARTBEAT
    if isinstance(message, ServoCommand):
        return MsgType.SERVO_CMD
    if isinstance(message, Telemetry):
        return MsgType.TELEMETRY
    if isinstance(message, ErrorReport):
        return MsgType.ERROR
    raise TypeError(f'not a protocol message: {message!r}')


def pack_payload(message: Message) -> bytes:
    """Return the payload bytes of ``message``; raises ``struct.error``/``ValueError``."""
    if isinstance(message, Heartbeat):
        return _HEARTBEAT.pack(message.version, int(message.role),
                               message.uptime_ms & 0xFFFFFFFF)
    if isinstance(message, ServoCommand):
        return _SERVO_CMD.pack(message.servo_1, message.servo_2)
    if isinstance(message, Telemetry):
        return _TELEMETRY.pack(message.board_time_ms & 0xFFFFFFFF, message.roll, message.pitch,
                               message.yaw, *message.gyro, *message.accel, message.servo_1,
                               message.servo_2, message.battery_v, int(message.status))
    if isinstance(message, ErrorReport):
        return _ERROR.pack(int(message.code), message.ref_seq & 0xFFFF)
    raise TypeError(f'not a protocol message: {message!r}')


def unpack_payload(kind: int, payload: bytes) -> Message | None:
    """
    Return the message of type ``kind`` in ``payload``, or None if it is not a valid one.

    Valid means: known type, exact payload size, finite floats, known role. Never raises.
    """
    try:
        kind = MsgType(kind)
    except ValueError:
        return None
    if len(payload) != PAYLOAD_SIZES[kind]:
        return None
    if kind is MsgType.HEARTBEAT:
        version, role, uptime = _HEARTBEAT.unpack(payload)
        if role not in (Role.HOST, Role.FISH):
            return None
        return Heartbeat(version, Role(role), uptime)
    if kind is MsgType.SERVO_CMD:
        values = _SERVO_CMD.unpack(payload)
        return ServoCommand(*values) if all(map(math.isfinite, values)) else None
    if kind is MsgType.TELEMETRY:
        fields = _TELEMETRY.unpack(payload)
        floats = fields[1:13]
        if not all(map(math.isfinite, floats)):
            return None
        return Telemetry(board_time_ms=fields[0], roll=floats[0], pitch=floats[1],
                         yaw=floats[2], gyro=tuple(floats[3:6]), accel=tuple(floats[6:9]),
                         servo_1=floats[9], servo_2=floats[10], battery_v=floats[11],
                         status=fields[13])
    code, ref_seq = _ERROR.unpack(payload)
    return ErrorReport(code, ref_seq)
