"""
The firmware's host build from Python: the make step and ctypes bindings of wf_host.h.

``build_firmware`` runs ``make -C firmware`` once per process under a file lock (pytest-xdist
workers share the tree); ``FirmwareHost`` wraps ``build/host/libwirefish_fw.so``: the process's
one board (init, step at a time, snapshot, I2C device model, ADC) and the batch codec;
``random_messages`` draws valid messages as flat records and ``to_python`` makes the
wirefish_bridge message of one.
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import fcntl
from pathlib import Path
import subprocess

import numpy as np
from wirefish_bridge.protocol import (ErrorReport, Heartbeat, ProtocolMessage, Role, ServoCommand,
                                      Telemetry)

WORKSPACE = Path(__file__).resolve().parents[1]
FIRMWARE = WORKSPACE / 'firmware'
BUILD = FIRMWARE / 'build'
LIBRARY = BUILD / 'host' / 'libwirefish_fw.so'
FUZZ_DRIVER = BUILD / 'asan' / 'fuzz_decoder'

# wf_host_msg_t: every field of every message type, flat (firmware/port/host/wf_host.h).
MSG_DTYPE = np.dtype([('type', 'u1'), ('code', 'u1'), ('role', 'u1'), ('pad', 'u1'),
                      ('seq', '<u2'), ('ref', '<u2'), ('time', '<u4'), ('f', '<f4', (12,))])
# wf_decoder_stats_t, in order: the same names as the bridge's DecoderStats.
STATS_FIELDS = ('bytes_in', 'frames_ok', 'cobs_errors', 'short_frames', 'crc_errors',
                'unknown_type', 'length_errors', 'invalid_payload', 'overflows', 'resyncs',
                'seq_gaps', 'seq_resets')
I2cDevice = Callable[[int, bytes, int], 'bytes | None']
MESSAGE_TYPES = np.array([0x01, 0x10, 0x20, 0x7F], np.uint8)


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
    is_heartbeat = records['type'] == 0x01
    is_servo = records['type'] == 0x10
    is_telemetry = records['type'] == 0x20
    is_error = records['type'] == 0x7F
    # Only the fields a type carries (the C side leaves the others zero).
    records['time'][is_servo | is_error] = 0
    records['ref'][is_heartbeat | is_servo] = 0
    records['code'][is_servo | is_telemetry] = 0
    records['role'][~is_heartbeat] = 0
    records['f'][~(is_servo | is_telemetry)] = 0.0
    records['f'][is_servo, 2:] = 0.0
    return records


def to_python(record: np.void) -> ProtocolMessage:
    """Return the wirefish_bridge message of one record."""
    kind = int(record['type'])
    f = record['f'].tolist()
    if kind == 0x01:
        return Heartbeat(int(record['code']), Role(int(record['role'])), int(record['time']))
    if kind == 0x10:
        return ServoCommand(f[0], f[1])
    if kind == 0x20:
        return Telemetry(board_time_ms=int(record['time']), roll=f[0], pitch=f[1], yaw=f[2],
                         gyro=tuple(f[3:6]), accel=tuple(f[6:9]), servo_1=f[9],
                         servo_2=f[10], battery_v=f[11], status=int(record['ref']))
    return ErrorReport(int(record['code']), int(record['ref']))


def build_firmware(*targets: str) -> None:
    """Run ``make -C firmware`` for ``targets``; raise with make's output when it fails."""
    BUILD.mkdir(parents=True, exist_ok=True)
    with open(BUILD / '.make.lock', 'w') as lock:
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
                ('low_battery_v', ctypes.c_float)]


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
            'wf_host_decode_stream': (_SIZE, [_BYTES, _SIZE, ctypes.c_void_p, _SIZE,
                                              ctypes.c_void_p]),
            'wf_host_encode_stream': (_SIZE, [ctypes.c_void_p, _SIZE, ctypes.c_void_p, _SIZE]),
            'wf_config_defaults': (None, [ctypes.POINTER(Config)]),
        }
        for name, (restype, argtypes) in signatures.items():
            function = getattr(lib, name)
            function.restype = restype
            function.argtypes = argtypes
        if (lib.wf_host_config_size() != ctypes.sizeof(Config)
                or lib.wf_host_snapshot_size() != ctypes.sizeof(Snapshot)):
            raise RuntimeError('firmware_host.py and wf_host.h disagree on a structure')
        self.lib = lib
        self._out = ctypes.create_string_buffer(1 << 16)
        self._i2c: object = None  # the ctypes callback, kept alive while the board uses it

    def config_defaults(self) -> Config:
        """Return the firmware's default configuration (wf_config_defaults)."""
        config = Config()
        self.lib.wf_config_defaults(ctypes.byref(config))
        return config

    def reset(self, config: Config | None = None, i2c: I2cDevice | None = None,
              adc_raw: int = 3392, start_ms: int = 0) -> None:
        """Give a fresh board: HAL reset, the clock at ``start_ms``, devices, then wf_app_init."""
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
        capacity = 64 * len(messages) + 64
        out = ctypes.create_string_buffer(capacity)
        n = self.lib.wf_host_encode_stream(messages.ctypes.data, len(messages), out, capacity)
        if n == 0 and len(messages):
            raise ValueError('wf_host_encode_stream refused the batch (an unknown type?)')
        return out.raw[:n]
