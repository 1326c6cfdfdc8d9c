# SPDX-License-Identifier: Apache-2.0
"""
Messages of the wirefish serial protocol (see PROTOCOL.md) and their payload layouts.

Pure data: no I/O, no rclpy. A frame body is ``type (u8) | seq (u16 LE) | payload | crc16 (u16
LE)``; this module packs and unpacks the payloads, ``codec`` does framing, CRC and streaming.
All multi-byte fields are little-endian; angles in rad, rates in rad/s, accelerations in m/s^2,
voltages in V, times in ms of the sender's clock (TELEMETRY_COMPACT carries scaled integers:
``TelemetryCompact.expanded`` gives them back in SI units).

Validity at decode time (``from_wire``) is what a receiver judges without knowing the peer's
state: finite floats (HEARTBEAT's known role). The ranges of GAIT and LINK_CONFIG depend on
the board (its servo limit) and are answered, not dropped: ``Gait.problem`` and
``LinkConfig.problem`` say why the fish refuses one (ERROR/ACK 6).

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

PROTOCOL_VERSION = 2
DEFAULT_BAUDRATE = 115200


class MsgType(enum.IntEnum):
    """The message type byte."""

    HEARTBEAT = 0x01
    LINK_CONFIG = 0x02
    ACK = 0x03
    SERVO_CMD = 0x10
    GAIT = 0x11
    SERVO_TRIM = 0x12
    TELEMETRY = 0x20
    TELEMETRY_COMPACT = 0x21
    SERVO_TRIM_REPORT = 0x22
    HEALTH = 0x30
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
    NOT_NOW = 7          # a valid request refused in the fish's current mode (SERVO_TRIM)
    STORAGE_FAILED = 8   # the calibration could not be written: nothing changed


class Status(enum.IntFlag):
    """Status flags of a TELEMETRY / TELEMETRY_COMPACT message (u16)."""

    NONE = 0
    # Stream mode, no SERVO_CMD for the command timeout: slewing to (or holding) neutral at the
    # failsafe's bounded rate.
    FAILSAFE_COMMAND = 0x0001
    FAILSAFE_HEARTBEAT = 0x0002  # stream mode, no host HEARTBEAT for the heartbeat timeout
    SERVO_CLAMPED = 0x0004      # a target was beyond the mechanical limit
    LOW_BATTERY = 0x0008
    IMU_FAULT = 0x0010
    VERSION_MISMATCH = 0x0020   # the host's heartbeat announced another protocol version
    COASTING = 0x0040           # gait mode, link lost: still swimming the last gait (coast_ms)
    RESTING = 0x0080            # gait mode, link lost past the coast: brought to rest
    GAIT_MODE = 0x0100          # the board integrates eq 1 itself (clear: stream mode)
    CLOCK_FALLBACK = 0x0200     # running on the internal oscillator: the crystal failed


class TelemetryForm(enum.IntEnum):
    """Which telemetry message the fish sends (LINK_CONFIG's telemetry_form)."""

    FULL = 0     # TELEMETRY (0x20), binary32 values
    COMPACT = 1  # TELEMETRY_COMPACT (0x21), scaled integers


class ResetCause(enum.IntEnum):
    """Why the board last reset (HEALTH)."""

    UNKNOWN = 0
    POWER_ON = 1
    PIN = 2
    BROWN_OUT = 3
    IWDG = 4       # the independent watchdog: the poll loop stopped
    WWDG = 5
    SOFTWARE = 6
    FAULT = 7      # the fault handler's own reset: the fault_* fields are valid
    LOW_POWER = 8


class ClockSource(enum.IntEnum):
    """What clocks the board's CPU (HEALTH)."""

    HSE_PLL = 0    # 168 MHz from the crystal
    HSI_PLL = 1    # fallback: the crystal did not start or failed
    HSI = 2        # 16 MHz, no PLL
    EMULATED = 3   # an emulator (or the virtual fish): no clock tree to set up


class HealthFlags(enum.IntFlag):
    """Flags of a HEALTH message (u8)."""

    NONE = 0
    FAULT_RECORD = 0x01  # fault_pc, fault_lr, fault_cfsr, fault_hfsr are valid
    BOR_LEVEL3 = 0x02    # brown-out reset at 2.7 V confirmed
    CSS_ON = 0x04        # the clock security system is armed
    STACK_GUARD = 0x08   # a stack overflow faults instead of overwriting data


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


# LINK_CONFIG's ranges (inclusive) and the fish's defaults at boot (PROTOCOL.md).
TELEMETRY_PERIOD_RANGE_MS = (10, 1000)
HEALTH_PERIOD_RANGE_MS = (200, 60000)   # or 0: no periodic HEALTH
LINK_TIMEOUT_RANGE_MS = (100, 10000)
COAST_RANGE_MS = (0, 60000)


@dataclass(frozen=True)
class LinkConfig(ProtocolMessage, kind=MsgType.LINK_CONFIG, layout='<HBHHH'):
    """
    Host -> fish: how the fish uses the link; applied at once and ACKed.

    ``telemetry_period_ms`` (10..1000) and ``telemetry_form`` (TelemetryForm) of its telemetry,
    ``health_period_ms`` (0 off, else 200..60000), ``link_timeout_ms`` (100..10000: no valid
    host frame this long is a lost link in gait mode) and ``coast_ms`` (0..60000: how long the
    fish swims its gait on after that before coming to rest). The defaults are the fish's at
    boot. Any values decode (``problem`` says which the fish refuses).
    """

    telemetry_period_ms: int = 10
    telemetry_form: int = TelemetryForm.FULL
    health_period_ms: int = 2000
    link_timeout_ms: int = 1500
    coast_ms: int = 3000

    def to_wire(self) -> tuple[Any, ...]:
        """Return the five fields in order."""
        return (self.telemetry_period_ms, int(self.telemetry_form), self.health_period_ms,
                self.link_timeout_ms, self.coast_ms)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> LinkConfig:
        """Return the configuration (its ranges are the fish's to judge: ``problem``)."""
        period, form, health, timeout, coast = values
        return cls(period, TelemetryForm(form) if form in _FORMS else form, health, timeout,
                   coast)

    def problem(self) -> str | None:
        """Return why the fish refuses this configuration (a field out of range), or None."""
        checks = (('telemetry_period_ms', self.telemetry_period_ms, TELEMETRY_PERIOD_RANGE_MS),
                  ('link_timeout_ms', self.link_timeout_ms, LINK_TIMEOUT_RANGE_MS),
                  ('coast_ms', self.coast_ms, COAST_RANGE_MS))
        for name, value, (low, high) in checks:
            if not low <= value <= high:
                return f'{name} {value} outside [{low}, {high}]'
        low, high = HEALTH_PERIOD_RANGE_MS
        if self.health_period_ms != 0 and not low <= self.health_period_ms <= high:
            return f'health_period_ms {self.health_period_ms} neither 0 nor in [{low}, {high}]'
        if self.telemetry_form not in _FORMS:
            return f'telemetry_form {self.telemetry_form} is not a TelemetryForm'
        return None


_FORMS = frozenset(int(form) for form in TelemetryForm)


@dataclass(frozen=True)
class Ack(ProtocolMessage, kind=MsgType.ACK, layout='<BHB'):
    """
    Fish -> host: the answer to a GAIT, LINK_CONFIG or SERVO_TRIM with sequence ``acked_seq``.

    ``result`` 0: accepted; else the ErrorCode of the refusal (nothing changed).
    """

    acked_type: int
    acked_seq: int
    result: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return the acked type, seq (wrapped to u16) and the result."""
        return int(self.acked_type), self.acked_seq & 0xFFFF, int(self.result)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Ack:
        """Return the ACK (any values: an unknown type or result is still an answer)."""
        return cls(*values)

    @property
    def accepted(self) -> bool:
        """Return True when the acked frame took effect."""
        return self.result == 0


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


# GAIT's ranges (PROTOCOL.md): beyond them the fish answers ERROR 6 and ACK 6. |w| <= 100/s
# keeps the board's 1 ms RK4 accurate (coupling stiffness r (|w12| + |w21|) <= 314/s with
# r <= pi/2: h lambda <= 0.31); every phase bias has a representative within 2 pi.
GAIT_MAX_FREQUENCY_HZ = 10.0
GAIT_MAX_ALPHA = 200.0
GAIT_MAX_COUPLING = 100.0
GAIT_MAX_PHASE_BIAS = 2.0 * math.pi


@dataclass(frozen=True)
class Gait(ProtocolMessage, kind=MsgType.GAIT, layout='<H' + 'f' * 10):
    """
    Host -> fish: the parameters of eq 1 that the board integrates itself (gait mode).

    ``gait_id`` (1..65535) names the gait in the fish's telemetry; the rest are
    wirefish_cpg.oscillator.CpgParameters' fields: intrinsic frequency v (Hz), amplitude
    targets R_1, R_2 and offset targets B_1, B_2 (rad), couplings omega_12, omega_21 (1/s),
    phase biases phi_12, phi_21 (rad), convergence gain alpha (1/s).
    """

    gait_id: int
    frequency_hz: float
    amplitude_1: float
    amplitude_2: float
    offset_1: float = 0.0
    offset_2: float = 0.0
    w12: float = 0.0
    w21: float = 0.0
    phi12: float = 0.0
    phi21: float = 0.0
    alpha: float = 20.0

    def to_wire(self) -> tuple[Any, ...]:
        """Return the gait id (wrapped to u16) and the ten floats in order."""
        return (self.gait_id & 0xFFFF, self.frequency_hz, self.amplitude_1, self.amplitude_2,
                self.offset_1, self.offset_2, self.w12, self.w21, self.phi12, self.phi21,
                self.alpha)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Gait | None:
        """Return the gait, or None if a float is not finite (ranges: ``problem``)."""
        return cls(*values) if _finite(values[1:]) else None

    def problem(self, servo_limit_rad: float) -> str | None:
        """
        Return why a fish with servo limit ``servo_limit_rad`` refuses this gait, or None.

        Valid: gait_id != 0, 0 < frequency <= 10 Hz, 0 <= amplitude <= limit, |offset| <=
        limit, |w12|, |w21| <= 100 /s, |phi12|, |phi21| <= 2 pi, 0 < alpha <= 200 (and every
        float finite).
        """
        floats = self.to_wire()[1:]
        if not _finite(floats):
            return 'a parameter is not finite'
        if self.gait_id == 0:
            return 'gait_id 0 names no gait'
        if not 0.0 < self.frequency_hz <= GAIT_MAX_FREQUENCY_HZ:
            return f'frequency {self.frequency_hz:g} Hz outside (0, {GAIT_MAX_FREQUENCY_HZ:g}]'
        for name in ('amplitude_1', 'amplitude_2'):
            value = getattr(self, name)
            if not 0.0 <= value <= servo_limit_rad:
                return f'{name} {value:g} rad outside [0, {servo_limit_rad:g}]'
        for name in ('offset_1', 'offset_2'):
            value = getattr(self, name)
            if not abs(value) <= servo_limit_rad:
                return f'{name} {value:g} rad beyond the servo limit {servo_limit_rad:g}'
        for name in ('w12', 'w21'):
            value = getattr(self, name)
            if not abs(value) <= GAIT_MAX_COUPLING:
                return f'{name} {value:g} /s beyond +-{GAIT_MAX_COUPLING:g}'
        for name in ('phi12', 'phi21'):
            value = getattr(self, name)
            if not abs(value) <= GAIT_MAX_PHASE_BIAS:
                return f'{name} {value:g} rad beyond +-2 pi'
        if not 0.0 < self.alpha <= GAIT_MAX_ALPHA:
            return f'alpha {self.alpha:g} outside (0, {GAIT_MAX_ALPHA:g}]'
        return None


class TrimOp(enum.IntEnum):
    """What a SERVO_TRIM asks of the fish."""

    READ = 0      # report the servo's calibration, change nothing
    SET = 1       # use the given calibration now, not saved
    SAVE = 2      # use it now and write it to the board's storage
    FACTORY = 3   # back to the build's defaults, now and after a reboot


class CalibrationSource(enum.IntEnum):
    """Where a servo's calibration in force comes from (SERVO_TRIM_REPORT)."""

    DEFAULTS = 0  # the build's values
    STORED = 1    # equal to the record in the board's storage
    LIVE = 2      # set by SERVO_TRIM, not saved


SERVOS = (1, 2)  # servo_1 drives reel phi_D1, servo_2 reel phi_D2
_OPS = frozenset(int(op) for op in TrimOp)
_SOURCES = frozenset(int(source) for source in CalibrationSource)


@dataclass(frozen=True)
class ServoTrim(ProtocolMessage, kind=MsgType.SERVO_TRIM, layout='<BBbBff'):
    """
    Host -> fish: read, set, save or reset one servo's calibration; ACKed, then reported.

    ``servo`` 1 or 2, ``op`` a TrimOp, ``direction`` +1/-1 (SET/SAVE; READ and FACTORY send
    0), ``reserved`` 0, ``neutral_us`` the pulse at 0 rad, ``us_per_rad`` the pulse change per
    rad of reel angle (> 0). Any finite values decode (``problem`` says which the fish
    refuses, ACK 6).
    """

    servo: int
    op: int = TrimOp.READ
    direction: int = 0
    neutral_us: float = 0.0
    us_per_rad: float = 0.0
    reserved: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return servo, op, direction, reserved, neutral_us, us_per_rad."""
        return (self.servo, int(self.op), self.direction, self.reserved, self.neutral_us,
                self.us_per_rad)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> ServoTrim | None:
        """Return the request, or None if a float is not finite (ranges: ``problem``)."""
        servo, op, direction, reserved, neutral, per_rad = values
        if not _finite((neutral, per_rad)):
            return None
        return cls(servo, TrimOp(op) if op in _OPS else op, direction, neutral, per_rad,
                   reserved)

    def problem(self) -> str | None:
        """
        Return why the fish refuses this request whatever its state (ACK 6), or None.

        The fit of the calibration to the board's pulse range is the board's to judge
        (``wf_servo_cal_fits``): the host does not know its min_us/max_us before a report.
        """
        if self.servo not in SERVOS:
            return f'servo {self.servo} is neither 1 nor 2'
        if self.op not in _OPS:
            return f'op {self.op} is not a TrimOp'
        if self.reserved != 0:
            return f'reserved byte {self.reserved} is not 0'
        if self.op in (TrimOp.SET, TrimOp.SAVE):
            if self.direction not in (1, -1):
                return f'direction {self.direction} is neither +1 nor -1'
            if not _finite((self.neutral_us, self.us_per_rad)):
                return 'neutral_us and us_per_rad must be finite'
            if not self.us_per_rad > 0.0:
                return f'us_per_rad {self.us_per_rad:g} is not > 0'
        return None


@dataclass(frozen=True)
class ServoTrimReport(ProtocolMessage, kind=MsgType.SERVO_TRIM_REPORT, layout='<BBbBffff'):
    """
    Fish -> host: one servo's calibration in force and where it comes from.

    Sent after the ACK of an accepted SERVO_TRIM (that servo) and for both servos after boot.
    ``source`` a CalibrationSource; ``min_us``/``max_us`` the build's pulse range (read-only).
    Any finite values decode.
    """

    servo: int
    source: int
    direction: int
    neutral_us: float
    us_per_rad: float
    min_us: float
    max_us: float
    reserved: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return servo, source, direction, reserved and the four floats in order."""
        return (self.servo, int(self.source), self.direction, self.reserved, self.neutral_us,
                self.us_per_rad, self.min_us, self.max_us)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> ServoTrimReport | None:
        """Return the report, or None if a float is not finite."""
        servo, source, direction, reserved, neutral, per_rad, low, high = values
        if not _finite((neutral, per_rad, low, high)):
            return None
        return cls(servo, CalibrationSource(source) if source in _SOURCES else source,
                   direction, neutral, per_rad, low, high, reserved)


@dataclass(frozen=True)
class Telemetry(ProtocolMessage, kind=MsgType.TELEMETRY, layout='<I' + 'f' * 12 + 'HH'):
    """
    Fish -> host, every telemetry period: board time, attitude, IMU, servos, battery, status.

    ``roll``/``pitch``/``yaw`` (rad): ZYX intrinsic Euler angles of the IMU frame relative to
    the world frame (ENU, z up; yaw about z, counter-clockwise positive). ``gyro`` (rad/s) and
    ``accel`` (m/s^2, specific force: +9.81 on z at rest) are (x, y, z) in the IMU frame (FLU).
    ``gait_id``: the gait the board runs (0: stream mode, or none yet).
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
    gait_id: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return board time (wrapped to u32), the 12 floats in order, status, gait id."""
        return (self.board_time_ms & 0xFFFFFFFF, self.roll, self.pitch, self.yaw, *self.gyro,
                *self.accel, self.servo_1, self.servo_2, self.battery_v, int(self.status),
                self.gait_id & 0xFFFF)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Telemetry | None:
        """Return the telemetry, or None if a float is not finite (ranges: telemetry_limits)."""
        floats = values[1:13]
        if not _finite(floats):
            return None
        return cls(board_time_ms=values[0], roll=floats[0], pitch=floats[1], yaw=floats[2],
                   gyro=tuple(floats[3:6]), accel=tuple(floats[6:9]), servo_1=floats[9],
                   servo_2=floats[10], battery_v=floats[11], status=values[13],
                   gait_id=values[14])


# TELEMETRY_COMPACT's scales: one count of each field in SI units.
ANGLE_LSB_RAD = 1e-4        # roll, pitch, yaw, servo angles: +-3.2767 rad
RATE_LSB_RAD_S = 1e-3       # gyro: +-32.767 rad/s (the MPU6050's +-2000 deg/s saturates)
ACCEL_LSB_M_S2 = 1e-3       # accel: +-32.767 m/s^2 (3.3 g: a swimming fish's range)
BATTERY_LSB_V = 1e-3        # battery_mv: 0..65.535 V
_I16 = (-0x8000, 0x7FFF)
_U16 = (0, 0xFFFF)


def quantize(value: float, lsb: float, bounds: tuple[int, int] = _I16) -> int:
    """
    Return ``value`` in counts of ``lsb``: nearest, halves away from zero, saturated to bounds.

    A value beyond the field's range saturates (+-inf too); NaN gives 0.
    """
    if math.isnan(value):
        return 0
    low, high = bounds
    scaled = value / lsb
    if not math.isfinite(scaled):
        return high if scaled > 0 else low
    count = math.floor(abs(scaled) + 0.5)
    return max(low, min(high, count if scaled >= 0 else -count))


@dataclass(frozen=True)
class TelemetryCompact(ProtocolMessage, kind=MsgType.TELEMETRY_COMPACT,
                       layout='<I' + 'h' * 11 + 'HHH'):
    """
    Fish -> host: TELEMETRY in 32 bytes for narrow links; the same fields as scaled integers.

    Counts of ``ANGLE_LSB_RAD`` (``roll``, ``pitch``, ``yaw``, ``servo_1``, ``servo_2``),
    ``RATE_LSB_RAD_S`` (``gyro``), ``ACCEL_LSB_M_S2`` (``accel``); ``battery_mv`` (mV),
    ``status`` and ``gait_id`` as in TELEMETRY. ``expanded`` returns the Telemetry in SI units,
    ``from_telemetry`` the compact form of one (the fish's rounding and saturation).
    """

    board_time_ms: int
    roll: int
    pitch: int
    yaw: int
    gyro: tuple[int, int, int]
    accel: tuple[int, int, int]
    servo_1: int
    servo_2: int
    battery_mv: int
    status: int = 0
    gait_id: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return board time (wrapped to u32), the eleven i16 counts, battery, status, gait."""
        return (self.board_time_ms & 0xFFFFFFFF, self.roll, self.pitch, self.yaw, *self.gyro,
                *self.accel, self.servo_1, self.servo_2, self.battery_mv, int(self.status),
                self.gait_id & 0xFFFF)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> TelemetryCompact:
        """Return the compact telemetry (every value decodes; ranges: telemetry_limits)."""
        return cls(board_time_ms=values[0], roll=values[1], pitch=values[2], yaw=values[3],
                   gyro=tuple(values[4:7]), accel=tuple(values[7:10]), servo_1=values[10],
                   servo_2=values[11], battery_mv=values[12], status=values[13],
                   gait_id=values[14])

    @classmethod
    def from_telemetry(cls, telemetry: Telemetry) -> TelemetryCompact:
        """Return the compact form of ``telemetry``, as the fish rounds and saturates it."""
        t = telemetry
        return cls(board_time_ms=t.board_time_ms,
                   roll=quantize(t.roll, ANGLE_LSB_RAD), pitch=quantize(t.pitch, ANGLE_LSB_RAD),
                   yaw=quantize(t.yaw, ANGLE_LSB_RAD),
                   gyro=_counts(t.gyro, RATE_LSB_RAD_S), accel=_counts(t.accel, ACCEL_LSB_M_S2),
                   servo_1=quantize(t.servo_1, ANGLE_LSB_RAD),
                   servo_2=quantize(t.servo_2, ANGLE_LSB_RAD),
                   battery_mv=quantize(t.battery_v, BATTERY_LSB_V, _U16),
                   status=int(t.status), gait_id=t.gait_id)

    def expanded(self) -> Telemetry:
        """Return the same fields as a Telemetry in SI units (rad, rad/s, m/s^2, V)."""
        return Telemetry(board_time_ms=self.board_time_ms, roll=self.roll * ANGLE_LSB_RAD,
                         pitch=self.pitch * ANGLE_LSB_RAD, yaw=self.yaw * ANGLE_LSB_RAD,
                         gyro=_scaled(self.gyro, RATE_LSB_RAD_S),
                         accel=_scaled(self.accel, ACCEL_LSB_M_S2),
                         servo_1=self.servo_1 * ANGLE_LSB_RAD,
                         servo_2=self.servo_2 * ANGLE_LSB_RAD,
                         battery_v=self.battery_mv * BATTERY_LSB_V, status=self.status,
                         gait_id=self.gait_id)


def _counts(xyz: tuple[float, float, float], lsb: float) -> tuple[int, int, int]:
    return quantize(xyz[0], lsb), quantize(xyz[1], lsb), quantize(xyz[2], lsb)


def _scaled(xyz: tuple[int, int, int], lsb: float) -> tuple[float, float, float]:
    return xyz[0] * lsb, xyz[1] * lsb, xyz[2] * lsb


def telemetry_of(message: ProtocolMessage) -> Telemetry | None:
    """Return the Telemetry that ``message`` carries in either form, or None for other types."""
    if isinstance(message, Telemetry):
        return message
    if isinstance(message, TelemetryCompact):
        return message.expanded()
    return None


@dataclass(frozen=True)
class Health(ProtocolMessage, kind=MsgType.HEALTH,
             layout='<BBB' + 'I' * 5 + 'HH' + 'I' * 7 + 'HHH'):
    """
    Fish -> host, every health period and once right after boot: what the board knows of itself.

    Why it last reset (``reset_cause``, a ResetCause; with FAULT the ``fault_*`` registers of
    the fault, flagged by HealthFlags.FAULT_RECORD), its clock (ClockSource), ``flags``
    (HealthFlags), uptime (ms), the stack's high-water mark (``stack_free_min`` bytes never
    written of ``stack_size``), UART receive overruns, transmit bytes dropped, the decoder's
    drops (CRC; COBS, short and over-long runs; unknown type; length; invalid values) and the
    IMU's faults, recoveries and I2C bus recoveries (u16, saturating). Any values decode.
    """

    reset_cause: int = ResetCause.UNKNOWN
    clock_source: int = ClockSource.HSE_PLL
    flags: int = 0
    fault_pc: int = 0
    fault_lr: int = 0
    fault_cfsr: int = 0
    fault_hfsr: int = 0
    uptime_ms: int = 0
    stack_free_min: int = 0
    stack_size: int = 0
    uart_rx_overruns: int = 0
    tx_bytes_dropped: int = 0
    rx_crc: int = 0
    rx_frame: int = 0
    rx_unknown_type: int = 0
    rx_length: int = 0
    rx_invalid: int = 0
    imu_faults: int = 0
    imu_recoveries: int = 0
    i2c_bus_recoveries: int = 0

    def to_wire(self) -> tuple[Any, ...]:
        """Return every field in order (the u32 counters wrapped)."""
        return (int(self.reset_cause), int(self.clock_source), int(self.flags),
                self.fault_pc, self.fault_lr, self.fault_cfsr, self.fault_hfsr,
                self.uptime_ms & 0xFFFFFFFF, self.stack_free_min, self.stack_size,
                *(v & 0xFFFFFFFF for v in (self.uart_rx_overruns, self.tx_bytes_dropped,
                                           self.rx_crc, self.rx_frame, self.rx_unknown_type,
                                           self.rx_length, self.rx_invalid)),
                self.imu_faults, self.imu_recoveries, self.i2c_bus_recoveries)

    @classmethod
    def from_wire(cls, values: tuple[Any, ...]) -> Health:
        """Return the report (any values: an unknown cause or clock is still worth showing)."""
        cause, clock = values[0], values[1]
        return cls(ResetCause(cause) if cause in _CAUSES else cause,
                   ClockSource(clock) if clock in _CLOCKS else clock, *values[2:])


_CAUSES = frozenset(int(cause) for cause in ResetCause)
_CLOCKS = frozenset(int(clock) for clock in ClockSource)


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
