# SPDX-License-Identifier: Apache-2.0
"""
The firmware's host build from Python: the make step and ctypes bindings of wf_host.h.

``build_firmware`` runs ``make -C firmware`` once per process under a file lock (pytest-xdist
workers share the tree); ``FirmwareHost`` wraps ``build/host/libwirefish_fw.so``: the process's
one board (init, step at a time, snapshots of its state, its gait mode and its health, I2C
device model, ADC) and the batch codec; ``random_messages`` draws valid messages of
every type as flat records, ``to_python`` makes the wirefish_bridge message of one and
``to_record`` the record of a message.
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import fcntl
from pathlib import Path
import subprocess

import numpy as np
from wirefish_bridge.protocol import (Ack, ErrorReport, Gait, Health, Heartbeat, LinkConfig,
                                      MsgType, ProtocolMessage, Role, ServoCommand, ServoTrim,
                                      ServoTrimReport, Telemetry, TelemetryCompact)
from wirefish_launcher.qemu_board import BUILD_LOCK

WORKSPACE = Path(__file__).resolve().parents[2]
FIRMWARE = WORKSPACE / 'firmware'
BUILD = FIRMWARE / 'build'
LIBRARY = BUILD / 'host' / 'libwirefish_fw.so'
FUZZ_DRIVER = BUILD / 'asan' / 'fuzz_decoder'

# wf_host_msg_t: every field of every message type, flat (firmware/port/host/wf_host.h); ``n``
# holds the integer fields the first part has no place for, widened, in wire order.
MSG_INTS = 20
MSG_DTYPE = np.dtype([('type', 'u1'), ('code', 'u1'), ('role', 'u1'), ('pad', 'u1'),
                      ('seq', '<u2'), ('ref', '<u2'), ('time', '<u4'), ('f', '<f4', (12,)),
                      ('pad2', '<u4'), ('n', '<i8', (MSG_INTS,))])
# wf_decoder_stats_t, in order: the same names as the bridge's DecoderStats.
STATS_FIELDS = ('bytes_in', 'frames_ok', 'cobs_errors', 'short_frames', 'crc_errors',
                'unknown_type', 'length_errors', 'invalid_payload', 'overflows', 'resyncs',
                'seq_gaps', 'seq_resets')
I2cDevice = Callable[[int, bytes, int], 'bytes | None']
MESSAGE_TYPES = np.array([int(kind) for kind in MsgType], np.uint8)
U8, I8, U16, I16 = (0, 0xFF), (-0x80, 0x7F), (0, 0xFFFF), (-0x8000, 0x7FFF)
U32 = (0, 0xFFFFFFFF)
# The ranges of the integers in ``n`` per type (wire order); a type not named has none there.
INT_FIELDS: dict[int, tuple[tuple[int, int], ...]] = {
    MsgType.TELEMETRY: (U16,),
    MsgType.LINK_CONFIG: (U16, U8, U16, U16, U16),
    MsgType.ACK: (U8, U16, U8),
    MsgType.GAIT: (U16,),
    MsgType.TELEMETRY_COMPACT: (U32,) + (I16,) * 11 + (U16,) * 3,
    MsgType.HEALTH: (U8,) * 3 + (U32,) * 5 + (U16,) * 2 + (U32,) * 7 + (U16,) * 3,
    # SERVO_TRIM, SERVO_TRIM_REPORT: servo, op or source, direction, reserved.
    MsgType.SERVO_TRIM: (U8, U8, I8, U8),
    MsgType.SERVO_TRIM_REPORT: (U8, U8, I8, U8),
}
# How many of ``f`` each type carries (SERVO_TRIM: neutral_us, us_per_rad; SERVO_TRIM_REPORT:
# those, min_us, max_us).
FLOATS = {MsgType.SERVO_CMD: 2, MsgType.GAIT: 10, MsgType.TELEMETRY: 12, MsgType.SERVO_TRIM: 2,
          MsgType.SERVO_TRIM_REPORT: 4}


def random_messages(rng: np.random.Generator, count: int) -> np.ndarray:
    """Return ``count`` random valid messages (MSG_DTYPE): any seq, any value a field may hold."""
    records = np.zeros(count, MSG_DTYPE)
    records['type'] = rng.choice(MESSAGE_TYPES, count)
    records['seq'] = rng.integers(0, 1 << 16, count)
    records['time'] = rng.integers(0, 1 << 32, count, dtype=np.uint64)
    records['ref'] = rng.integers(0, 1 << 16, count)
    records['code'] = rng.integers(0, 256, count)
    records['role'] = rng.integers(0, 2, count)
    bits = rng.integers(0, 1 << 32, (count, 12), dtype=np.uint64).astype(np.uint32)
    not_finite = (bits & 0x7F800000) == 0x7F800000
    bits[not_finite] &= 0xBFFFFFFF  # clear the top exponent bit: finite, sign kept
    bits[rng.random((count, 12)) < 0.02] = 0x80000000  # -0.0 is a value of its own
    records['f'] = bits.view(np.float32)
    # Integers of every width at their edges now and then: 0, the extremes, one inside.
    edges = rng.random((count, MSG_INTS)) < 0.05
    uniform = rng.random((count, MSG_INTS))
    types = records['type']
    is_heartbeat = types == MsgType.HEARTBEAT
    is_telemetry = types == MsgType.TELEMETRY
    is_error = types == MsgType.ERROR
    # Only the fields a type carries (the C side leaves the others zero).
    records['time'][~(is_heartbeat | is_telemetry)] = 0
    records['ref'][~(is_telemetry | is_error)] = 0
    records['code'][~(is_heartbeat | is_error)] = 0
    records['role'][~is_heartbeat] = 0
    for kind in MsgType:
        rows = types == kind
        records['f'][rows, FLOATS.get(kind, 0):] = 0.0
        for i, (low, high) in enumerate(INT_FIELDS.get(kind, ())):
            values = np.floor(low + uniform[rows, i] * (high - low + 1)).astype(np.int64)
            pick = edges[rows, i]
            values[pick] = np.where(uniform[rows, i][pick] < 0.5, low, high)
            records['n'][rows, i] = np.minimum(values, high)
    return records


def to_python(record: np.void) -> ProtocolMessage:
    """Return the wirefish_bridge message of one record."""
    kind = int(record['type'])
    f = record['f'].tolist()
    n = [int(v) for v in record['n']]
    if kind == MsgType.HEARTBEAT:
        return Heartbeat(int(record['code']), Role(int(record['role'])), int(record['time']))
    if kind == MsgType.SERVO_CMD:
        return ServoCommand(f[0], f[1])
    if kind == MsgType.TELEMETRY:
        return Telemetry(board_time_ms=int(record['time']), roll=f[0], pitch=f[1], yaw=f[2],
                         gyro=tuple(f[3:6]), accel=tuple(f[6:9]), servo_1=f[9],
                         servo_2=f[10], battery_v=f[11], status=int(record['ref']),
                         gait_id=n[0])
    if kind == MsgType.LINK_CONFIG:
        return LinkConfig(*n[:5])
    if kind == MsgType.ACK:
        return Ack(*n[:3])
    if kind == MsgType.GAIT:
        return Gait(n[0], *f[:10])
    if kind == MsgType.TELEMETRY_COMPACT:
        return TelemetryCompact(n[0], n[1], n[2], n[3], tuple(n[4:7]), tuple(n[7:10]), n[10],
                                n[11], n[12], n[13], n[14])
    if kind == MsgType.HEALTH:
        return Health(*n[:20])
    if kind == MsgType.SERVO_TRIM:
        return ServoTrim(servo=n[0], op=n[1], direction=n[2], neutral_us=f[0],
                         us_per_rad=f[1], reserved=n[3])
    if kind == MsgType.SERVO_TRIM_REPORT:
        return ServoTrimReport(servo=n[0], source=n[1], direction=n[2], neutral_us=f[0],
                               us_per_rad=f[1], min_us=f[2], max_us=f[3], reserved=n[3])
    if kind == MsgType.ERROR:
        return ErrorReport(int(record['code']), int(record['ref']))
    raise ValueError(f'to_python: no message for type 0x{kind:02x}')


def to_record(message: ProtocolMessage, seq: int) -> np.ndarray:
    """Return the one-record array (MSG_DTYPE) of ``message`` with ``seq``: to_python's inverse."""
    record = np.zeros(1, MSG_DTYPE)
    m = message
    kind = type(m).KIND
    record['type'], record['seq'] = int(kind), seq
    ints: list[int] = []
    if isinstance(m, Heartbeat):
        record['code'], record['role'], record['time'] = m.version, int(m.role), m.uptime_ms
    elif isinstance(m, ServoCommand):
        record['f'][0, :2] = (m.servo_1, m.servo_2)
    elif isinstance(m, Telemetry):
        record['time'], record['ref'] = m.board_time_ms, int(m.status)
        record['f'][0] = (m.roll, m.pitch, m.yaw, *m.gyro, *m.accel, m.servo_1, m.servo_2,
                          m.battery_v)
        ints = [m.gait_id]
    elif isinstance(m, ErrorReport):
        record['code'], record['ref'] = int(m.code), m.ref_seq
    elif isinstance(m, Gait):
        record['f'][0, :10] = m.to_wire()[1:]
        ints = [m.gait_id]
    elif isinstance(m, (ServoTrim, ServoTrimReport)):  # servo, op or source, direction, reserved
        wire = m.to_wire()
        ints = [int(v) for v in wire[:4]]
        record['f'][0, :len(wire) - 4] = wire[4:]
    else:  # LINK_CONFIG, ACK, TELEMETRY_COMPACT, HEALTH: integers only, in wire order
        ints = [int(v) for v in _flat(m.to_wire())]
    record['n'][0, :len(ints)] = ints
    return record


def _flat(values: tuple) -> list:
    return [v for value in values for v in (value if isinstance(value, tuple) else (value,))]


def build_firmware(*targets: str) -> None:
    """Run ``make -C firmware`` for ``targets``; raise with make's output when it fails."""
    BUILD.mkdir(parents=True, exist_ok=True)
    with open(BUILD / BUILD_LOCK, 'w') as lock:  # qemu_board.build_image's turns too
        fcntl.flock(lock, fcntl.LOCK_EX)
        result = subprocess.run(['make', '-s', '-C', str(FIRMWARE), *targets],
                                capture_output=True, text=True, timeout=300)
    if result.returncode != 0:
        raise RuntimeError(f'make -C firmware {" ".join(targets)} failed:\n'
                           f'{result.stdout}{result.stderr}')


class ServoCal(ctypes.Structure):
    """wf_servo_cal_t."""

    _fields_ = [('neutral_us', ctypes.c_float), ('us_per_rad', ctypes.c_float),
                ('direction', ctypes.c_int8), ('min_us', ctypes.c_float),
                ('max_us', ctypes.c_float)]


class Config(ctypes.Structure):
    """wf_config_t (firmware/include/wf/app_state.h)."""

    _fields_ = [('command_timeout_ms', ctypes.c_uint32), ('heartbeat_timeout_ms', ctypes.c_uint32),
                ('telemetry_period_ms', ctypes.c_uint32), ('heartbeat_period_ms', ctypes.c_uint32),
                ('imu_period_ms', ctypes.c_uint32), ('servo_frame_hz', ctypes.c_uint32),
                ('servo_limit_rad', ctypes.c_float), ('servo_cal', ServoCal * 2),
                ('imu_axes', ctypes.c_int8 * 3), ('imu_mode', ctypes.c_uint8),
                ('attitude_tau_s', ctypes.c_float), ('battery_v_per_count', ctypes.c_float),
                ('low_battery_v', ctypes.c_float), ('health_period_ms', ctypes.c_uint32),
                ('link_timeout_ms', ctypes.c_uint32), ('coast_ms', ctypes.c_uint32),
                ('telemetry_form', ctypes.c_uint8), ('failsafe_slew_rad_s', ctypes.c_float)]


class CpgParams(ctypes.Structure):
    """wf_cpg_params_t (firmware/include/wf/cpg.h): GAIT's floats in wire order."""

    _fields_ = [('frequency_hz', ctypes.c_float), ('amplitude', ctypes.c_float * 2),
                ('offset', ctypes.c_float * 2), ('w12', ctypes.c_float),
                ('w21', ctypes.c_float), ('phi12', ctypes.c_float), ('phi21', ctypes.c_float),
                ('alpha', ctypes.c_float)]


class GaitSnapshot(ctypes.Structure):
    """wf_host_gait_snapshot_t: the board's gait mode, CPG and link settings."""

    _fields_ = [('gait_mode', ctypes.c_uint8), ('gap', ctypes.c_uint8),
                ('gait_id', ctypes.c_uint16), ('cpg_time_ms', ctypes.c_uint32),
                ('cpg_steps', ctypes.c_uint32), ('phase', ctypes.c_float * 2),
                ('r', ctypes.c_float * 2), ('dr', ctypes.c_float * 2),
                ('b', ctypes.c_float * 2), ('db', ctypes.c_float * 2),
                ('output', ctypes.c_float * 2), ('rate', ctypes.c_float * 2),
                ('target', ctypes.c_float * 2), ('compare', ctypes.c_uint32 * 2),
                ('status', ctypes.c_uint16), ('ack_count', ctypes.c_uint8),
                ('telemetry_form', ctypes.c_uint8), ('acks_dropped', ctypes.c_uint32),
                ('gaits_accepted', ctypes.c_uint32), ('gaits_refused', ctypes.c_uint32),
                ('telemetry_period_ms', ctypes.c_uint32), ('health_period_ms', ctypes.c_uint32),
                ('link_timeout_ms', ctypes.c_uint32), ('coast_ms', ctypes.c_uint32),
                ('params', CpgParams)]


class HealthRecord(ctypes.Structure):
    """wf_health_t (firmware/include/wf/health.h)."""

    _fields_ = [('reset_cause', ctypes.c_uint8), ('clock_source', ctypes.c_uint8),
                ('flags', ctypes.c_uint8), ('fault_pc', ctypes.c_uint32),
                ('fault_lr', ctypes.c_uint32), ('fault_cfsr', ctypes.c_uint32),
                ('fault_hfsr', ctypes.c_uint32), ('uptime_ms', ctypes.c_uint32),
                ('stack_free_min', ctypes.c_uint16), ('stack_size', ctypes.c_uint16),
                ('uart_rx_overruns', ctypes.c_uint32), ('tx_bytes_dropped', ctypes.c_uint32),
                ('rx_crc', ctypes.c_uint32), ('rx_frame', ctypes.c_uint32),
                ('rx_unknown_type', ctypes.c_uint32), ('rx_length', ctypes.c_uint32),
                ('rx_invalid', ctypes.c_uint32), ('imu_faults', ctypes.c_uint16),
                ('imu_recoveries', ctypes.c_uint16), ('i2c_bus_recoveries', ctypes.c_uint16)]


class CalibrationReport(ctypes.Structure):
    """wf_servo_trim_report_t: one servo's calibration in force and its source."""

    _fields_ = [('servo', ctypes.c_uint8), ('source', ctypes.c_uint8),
                ('direction', ctypes.c_int8), ('reserved', ctypes.c_uint8),
                ('neutral_us', ctypes.c_float), ('us_per_rad', ctypes.c_float),
                ('min_us', ctypes.c_float), ('max_us', ctypes.c_float)]


class Snapshot(ctypes.Structure):
    """wf_host_snapshot_t: a flat view of the board."""

    _fields_ = [('now_ms', ctypes.c_uint32), ('status', ctypes.c_uint16),
                ('host_seen', ctypes.c_uint8), ('host_version_ok', ctypes.c_uint8),
                ('commanded', ctypes.c_float * 2), ('target', ctypes.c_float * 2),
                ('compare', ctypes.c_uint32 * 2), ('roll', ctypes.c_float),
                ('pitch', ctypes.c_float), ('yaw', ctypes.c_float),
                ('gyro', ctypes.c_float * 3), ('accel', ctypes.c_float * 3),
                ('raw_accel', ctypes.c_int16 * 3), ('raw_gyro', ctypes.c_int16 * 3),
                ('battery_v', ctypes.c_float), ('commands_applied', ctypes.c_uint32),
                ('commands_ignored', ctypes.c_uint32), ('frames_sent', ctypes.c_uint32),
                ('errors_sent', ctypes.c_uint32), ('tx_bytes_dropped', ctypes.c_uint32),
                ('decoder', ctypes.c_uint32 * 12), ('config_rejected', ctypes.c_uint8)]


_I2C_FN = ctypes.CFUNCTYPE(ctypes.c_bool, ctypes.c_void_p, ctypes.c_uint8,
                           ctypes.POINTER(ctypes.c_uint8), ctypes.c_size_t,
                           ctypes.POINTER(ctypes.c_uint8), ctypes.c_size_t)
_BYTES = ctypes.c_char_p
_SIZE = ctypes.c_size_t


class FirmwareHost:
    """The host build's C API: one board per process, and the batch codec."""

    def __init__(self, path: Path = LIBRARY) -> None:
        """Load the library and check that the structures here match its own."""
        lib = ctypes.CDLL(str(path))
        signatures = {
            'wf_host_reset': (None, []),
            'wf_host_set_millis': (None, [ctypes.c_uint32]),
            'wf_host_set_adc_raw': (None, [ctypes.c_int32]),
            'wf_host_set_tx_capacity': (None, [_SIZE]),
            'wf_host_set_i2c_device': (None, [_I2C_FN, ctypes.c_void_p]),
            'wf_host_compare': (ctypes.c_uint32, [ctypes.c_uint]),
            'wf_host_board_init': (None, [ctypes.POINTER(Config)]),
            'wf_host_board_step': (_SIZE, [ctypes.c_uint32, _BYTES, _SIZE, ctypes.c_void_p,
                                           _SIZE]),
            'wf_host_board_snapshot': (None, [ctypes.POINTER(Snapshot)]),
            'wf_host_config_size': (_SIZE, []),
            'wf_host_snapshot_size': (_SIZE, []),
            'wf_host_board_gait': (None, [ctypes.POINTER(GaitSnapshot)]),
            'wf_host_gait_snapshot_size': (_SIZE, []),
            'wf_host_board_health': (None, [ctypes.POINTER(HealthRecord)]),
            'wf_host_health_size': (_SIZE, []),
            'wf_host_msg_size': (_SIZE, []),
            'wf_host_cpg_params_size': (_SIZE, []),
            'wf_host_decode_stream': (_SIZE, [_BYTES, _SIZE, ctypes.c_void_p, _SIZE,
                                              ctypes.c_void_p]),
            'wf_host_encode_stream': (_SIZE, [ctypes.c_void_p, _SIZE, ctypes.c_void_p, _SIZE]),
            'wf_config_defaults': (None, [ctypes.POINTER(Config)]),
            'wf_host_board_calibration': (None, [ctypes.POINTER(CalibrationReport * 2)]),
            'wf_host_calibration_size': (_SIZE, []),
            'wf_host_storage_clear': (None, []),
            'wf_host_storage_set_fault': (None, [ctypes.c_int]),
            'wf_host_storage_peek': (_SIZE, [ctypes.c_uint32, ctypes.c_void_p, _SIZE]),
            'wf_host_storage_poke': (_SIZE, [ctypes.c_uint32, _BYTES, _SIZE]),
        }
        for name, (restype, argtypes) in signatures.items():
            function = getattr(lib, name)
            function.restype = restype
            function.argtypes = argtypes
        sizes = {'wf_config_t': (lib.wf_host_config_size(), ctypes.sizeof(Config)),
                 'wf_host_snapshot_t': (lib.wf_host_snapshot_size(), ctypes.sizeof(Snapshot)),
                 'wf_host_gait_snapshot_t': (lib.wf_host_gait_snapshot_size(),
                                             ctypes.sizeof(GaitSnapshot)),
                 'wf_health_t': (lib.wf_host_health_size(), ctypes.sizeof(HealthRecord)),
                 'wf_host_msg_t': (lib.wf_host_msg_size(), MSG_DTYPE.itemsize),
                 'wf_cpg_params_t': (lib.wf_host_cpg_params_size(), ctypes.sizeof(CpgParams)),
                 'wf_servo_trim_report_t': (lib.wf_host_calibration_size(),
                                            ctypes.sizeof(CalibrationReport))}
        wrong = {name: size for name, size in sizes.items() if size[0] != size[1]}
        if wrong:
            raise RuntimeError(f'firmware_host.py and wf_host.h disagree on {wrong} '
                               '(C size, Python size)')
        self.lib = lib
        self._out = ctypes.create_string_buffer(1 << 16)
        self._i2c: object = None  # the ctypes callback, kept alive while the board uses it

    def config_defaults(self) -> Config:
        """Return the firmware's default configuration (wf_config_defaults)."""
        config = Config()
        self.lib.wf_config_defaults(ctypes.byref(config))
        return config

    def reset(self, config: Config | None = None, i2c: I2cDevice | None = None,
              adc_raw: int = 3392, start_ms: int = 0, keep_storage: bool = False) -> None:
        """Give a fresh board (the storage erased unless ``keep_storage``), then wf_app_init."""
        if not keep_storage:
            self.lib.wf_host_storage_clear()
        self.lib.wf_host_reset()
        self.lib.wf_host_set_millis(start_ms)
        self.lib.wf_host_set_adc_raw(adc_raw)
        self.set_i2c_device(i2c)
        self.lib.wf_host_board_init(ctypes.byref(config) if config is not None else None)

    def set_i2c_device(self, device: I2cDevice | None) -> None:
        """Route I2C to ``device(address, tx, rx_len) -> rx bytes or None (NACK)``."""
        if device is None:
            self._i2c = _I2C_FN()
            self.lib.wf_host_set_i2c_device(self._i2c, None)
            return

        def transfer(_context, address, tx, tx_len, rx, rx_len):
            answer = device(address, ctypes.string_at(tx, tx_len) if tx_len else b'', rx_len)
            if answer is None:
                return False
            ctypes.memmove(rx, bytes(answer), rx_len)
            return True

        self._i2c = _I2C_FN(transfer)
        self.lib.wf_host_set_i2c_device(self._i2c, None)

    def set_adc_raw(self, raw: int) -> None:
        """Set what the battery ADC reads (negative: no conversion)."""
        self.lib.wf_host_set_adc_raw(raw)

    def step(self, t_ms: int, data: bytes = b'') -> bytes:
        """Feed ``data`` at time ``t_ms``, poll once, return what the board sent."""
        n = self.lib.wf_host_board_step(t_ms & 0xFFFFFFFF, data, len(data), self._out,
                                        len(self._out))
        return self._out.raw[:n]

    def snapshot(self) -> Snapshot:
        """Return the board's state now."""
        snapshot = Snapshot()
        self.lib.wf_host_board_snapshot(ctypes.byref(snapshot))
        return snapshot

    def gait(self) -> GaitSnapshot:
        """Return the board's gait mode, CPG state and link settings now."""
        snapshot = GaitSnapshot()
        self.lib.wf_host_board_gait(ctypes.byref(snapshot))
        return snapshot

    def health(self) -> HealthRecord:
        """Return the board's health record as last sent."""
        record = HealthRecord()
        self.lib.wf_host_board_health(ctypes.byref(record))
        return record

    def calibration(self) -> list[CalibrationReport]:
        """Return both servos' calibration in force and its source (servo 1 first)."""
        reports = (CalibrationReport * 2)()
        self.lib.wf_host_board_calibration(ctypes.byref(reports))
        return list(reports)

    def storage(self, offset: int = 0, length: int = 16384) -> bytes:
        """Return ``length`` bytes of the calibration's storage from ``offset``."""
        out = ctypes.create_string_buffer(length)
        n = self.lib.wf_host_storage_peek(offset, out, length)
        return out.raw[:n]

    def poke_storage(self, offset: int, data: bytes) -> None:
        """Write ``data`` into the calibration's storage as it is (no flash rule)."""
        if self.lib.wf_host_storage_poke(offset, data, len(data)) != len(data):
            raise ValueError(f'{len(data)} bytes at {offset} do not fit the storage')

    def set_storage_fault(self, fault: int) -> None:
        """Make the storage fail (wf_host_storage_fault_t; 0: work again)."""
        self.lib.wf_host_storage_set_fault(fault)

    def compare(self, servo: int) -> int:
        """Return the compare value last written to servo channel 0 or 1."""
        return int(self.lib.wf_host_compare(servo))

    def decode_stream(self, data: bytes, max_frames: int | None = None
                      ) -> tuple[np.ndarray, dict[str, int]]:
        """Decode ``data`` in C; return the frames (MSG_DTYPE) and the decoder's counters."""
        capacity = max_frames if max_frames is not None else len(data) // 7 + 1
        out = np.zeros(capacity, MSG_DTYPE)
        stats = np.zeros(12, np.uint32)
        n = self.lib.wf_host_decode_stream(data, len(data), out.ctypes.data, capacity,
                                           stats.ctypes.data)
        return out[:n], dict(zip(STATS_FIELDS, stats.tolist()))

    def encode_stream(self, messages: np.ndarray) -> bytes:
        """Encode ``messages`` (MSG_DTYPE, their own seq) in C, frame after frame."""
        messages = np.ascontiguousarray(messages, MSG_DTYPE)
        capacity = 70 * len(messages) + 70
        out = ctypes.create_string_buffer(capacity)
        n = self.lib.wf_host_encode_stream(messages.ctypes.data, len(messages), out, capacity)
        if n == 0 and len(messages):
            raise ValueError('wf_host_encode_stream refused the batch (an unknown type?)')
        return out.raw[:n]
