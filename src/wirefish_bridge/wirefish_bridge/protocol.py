"""
Messages of the wirefish serial protocol (see PROTOCOL.md) and their payload layouts.

Pure data: no I/O, no rclpy. A frame body is ``type (u8) | seq (u16 LE) | payload | crc16 (u16
LE)``; this module packs and unpacks the payloads, ``codec`` does framing, CRC and streaming.
All multi-byte fields are little-endian; angles in rad, rates in rad/s, accelerations in m/s^2,
voltages in V, times in ms of the sender's clock.

One registry: a message is one class that subclasses ``ProtocolMessage`` with its type byte and
payload layout (``class X(ProtocolMessage, kind=MsgType.X, layout='<ff')``) and says how its
fields map to the layout (``to_wire``) and back (``from_wire``, which also judges validity).
``message_type``, ``pack_payload``, ``unpack_payload`` and ``PAYLOAD_SIZES`` read the registry;
a class that is not registered is refused with ``UnknownMessageError``, a type byte that is
not registered decodes to None (the codec counts it as ``unknown_type``). Adding a message: a
``MsgType`` member and its class (the import fails if either is missing), then PROTOCOL.md.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import enum
import math
import struct
from typing import Any, ClassVar, TypeVar

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


class UnknownMessageError(TypeError):
    """An object that is not a registered protocol message was given to be sent."""


_M = TypeVar('_M', bound='ProtocolMessage')
_BY_KIND: dict[int, type[ProtocolMessage]] = {}


class ProtocolMessage:
    """
    Base of every message; subclassing it with ``kind`` and ``layout`` registers the message.

    ``kind`` is the type byte (a ``MsgType``); ``layout`` the ``struct`` format of the payload
    (little-endian, fixed size). ``to_wire`` returns the values in ``layout`` order;
    ``from_wire`` builds the message from the unpacked values or returns None when they are not
    a valid message (it must not raise: it judges bytes from the wire).
    """

    KIND: ClassVar[MsgType]
    WIRE: ClassVar[struct.Struct]

    def __init_subclass__(cls, *, kind: MsgType, layout: str, **kwargs: Any) -> None:
        """Register ``cls`` as the message of type ``kind``; a type has one class only."""
        super().__init_subclass__(**kwargs)
        if not isinstance(kind, MsgType):
            raise TypeError(f'{cls.__name__}: kind must be a MsgType, got {kind!r}')
        if kind in _BY_KIND:
            raise ValueError(f'{cls.__name__}: type {kind.name} (0x{kind:02x}) is already '
                             f'the message {_BY_KIND[kind].__name__}')
        cls.KIND = kind
        cls.WIRE = struct.Struct(layout)
        _BY_KIND[kind] = cls

    def to_wire(self) -> tuple[Any, ...]:
        """Return the payload values in ``layout`` order."""
        raise NotImplementedError(type(self).__name__)

    @classmethod
    def from_wire(cls: type[_M], values: tuple[Any, ...]) -> _M | None:
        """Return the message of the unpacked ``values``, or None if they are not valid."""
        raise NotImplementedError(cls.__name__)


def _finite(values: Sequence[float]) -> bool:
    return all(map(math.isfinite, values))


@dataclass(frozen=True)
class Heartbeat(ProtocolMessage, kind=MsgType.HEARTBEAT, layout='<BBI'):
    """Both ways, a few Hz: protocol version, sender role, sender uptime (ms, wraps)."""

    version: int = PROTOCOL_VERSION
    role: Role = Role.HOST
    uptime_ms: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return version, role, uptime (wrapped to u32)."""
        return self.version, int(self.role), self.uptime_ms & 0xFFFFFFFF

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Heartbeat | None:
        """Return the heartbeat, or None for an unknown role."""
        version, role, uptime = values
        if role not in (Role.HOST, Role.FISH):
            return None
        return cls(version, Role(role), uptime)


@dataclass(frozen=True)
class ServoCommand(ProtocolMessage, kind=MsgType.SERVO_CMD, layout='<ff'):
    """Host -> fish: target angles of servo 1 and 2 (rad, reel angle phi_D,i of eq 2)."""

    servo_1: float
    servo_2: float

    def to_wire(self) -> tuple[Any, ...]:
        """Return the two target angles."""
        return self.servo_1, self.servo_2

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> ServoCommand | None:
        """Return the command, or None if an angle is not finite."""
        return cls(*values) if _finite(values) else None


@dataclass(frozen=True)
class Telemetry(ProtocolMessage, kind=MsgType.TELEMETRY, layout='<I' + 'f' * 12 + 'H'):
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

    def to_wire(self) -> tuple[Any, ...]:
        """Return board time (wrapped to u32), the 12 floats in order, status."""
        return (self.board_time_ms & 0xFFFFFFFF, self.roll, self.pitch, self.yaw, *self.gyro,
                *self.accel, self.servo_1, self.servo_2, self.battery_v, int(self.status))

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Telemetry | None:
        """Return the telemetry, or None if a float is not finite (ranges: telemetry_limits)."""
        floats = values[1:13]
        if not _finite(floats):
            return None
        return cls(board_time_ms=values[0], roll=floats[0], pitch=floats[1], yaw=floats[2],
                   gyro=tuple(floats[3:6]), accel=tuple(floats[6:9]), servo_1=floats[9],
                   servo_2=floats[10], battery_v=floats[11], status=values[13])


@dataclass(frozen=True)
class ErrorReport(ProtocolMessage, kind=MsgType.ERROR, layout='<BH'):
    """Fish -> host: ``code`` (ErrorCode) about the received frame with sequence ``ref_seq``."""

    code: int
    ref_seq: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return code and ref_seq (wrapped to u16)."""
        return int(self.code), self.ref_seq & 0xFFFF

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> ErrorReport | None:
        """Return the report (any code: an unknown one is still worth reporting)."""
        return cls(*values)


Message = ProtocolMessage  # any registered message (the registry, not a list, says which)

_missing = [kind.name for kind in MsgType if kind not in _BY_KIND]
if _missing:  # a MsgType without its class would decode to nothing: fail at import instead
    raise ImportError(f'protocol: no message class for {", ".join(_missing)}')

PAYLOAD_SIZES: dict[MsgType, int] = {kind: _BY_KIND[kind].WIRE.size for kind in MsgType}


def message_class(kind: int) -> type[ProtocolMessage] | None:
    """Return the registered class of type byte ``kind``, or None if there is none."""
    return _BY_KIND.get(kind)


def _registered(message: object) -> type[ProtocolMessage]:
    if (not isinstance(message, ProtocolMessage)
            or _BY_KIND.get(message.KIND) is not type(message)):
        known = ', '.join(c.__name__ for c in _BY_KIND.values())
        raise UnknownMessageError(f'not a protocol message: {message!r} (the messages are '
                                  f'{known})')
    return type(message)


def message_type(message: ProtocolMessage) -> MsgType:
    """Return the type byte of ``message``; raises ``UnknownMessageError`` if unregistered."""
    return _registered(message).KIND


def pack_payload(message: ProtocolMessage) -> bytes:
    """Return the payload bytes of ``message``; raises ``UnknownMessageError``/``struct.error``."""
    cls = _registered(message)
    return cls.WIRE.pack(*message.to_wire())


def unpack_payload(kind: int, payload: bytes) -> ProtocolMessage | None:
    """
    Return the message of type ``kind`` in ``payload``, or None if it is not a valid one.

    Valid means: registered type, exact payload size, and the class's own checks (finite floats,
    known role). Never raises.
    """
    cls = _BY_KIND.get(kind)
    if cls is None or len(payload) != cls.WIRE.size:
        return None
    return cls.from_wire(cls.WIRE.unpack(payload))
