"""
Cross-language: 100,000 random valid messages through both codecs, both ways.

Encoded by wirefish_bridge.codec they decode in C to the same values, and encoded in C they
decode in Python to the same values; every field of every type, floats compared bit for bit
(finite binary32 of every kind: normal, subnormal, +-0).
"""

from firmware_host import FirmwareHost, MSG_DTYPE
import numpy as np
import pytest
from wirefish_bridge.codec import encode_frame, StreamDecoder
from wirefish_bridge.protocol import (ErrorReport, Heartbeat, Role, ServoCommand, Telemetry)

COUNT = 100_000
TYPES = np.array([0x01, 0x10, 0x20, 0x7F], np.uint8)


def random_messages(rng: np.random.Generator, count: int) -> np.ndarray:
    """Return ``count`` random valid messages (MSG_DTYPE): any seq, any value a field may hold."""
    records = np.zeros(count, MSG_DTYPE)
    records['type'] = rng.choice(TYPES, count)
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


def to_python(record: np.void):
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


def from_python(frame, records: np.ndarray, i: int) -> None:
    """Write a decoded Python frame into records[i]."""
    m = frame.message
    record = records[i]
    record['type'] = int(frame.kind)
    record['seq'] = frame.seq
    if isinstance(m, Heartbeat):
        record['code'], record['role'], record['time'] = m.version, int(m.role), m.uptime_ms
    elif isinstance(m, ServoCommand):
        record['f'][:2] = (m.servo_1, m.servo_2)
    elif isinstance(m, Telemetry):
        record['time'], record['ref'] = m.board_time_ms, m.status
        record['f'] = (m.roll, m.pitch, m.yaw, *m.gyro, *m.accel, m.servo_1, m.servo_2,
                       m.battery_v)
    else:
        record['code'], record['ref'] = m.code, m.ref_seq


@pytest.fixture(scope='module')
def messages() -> np.ndarray:
    """Return the random messages of this module (seeded)."""
    return random_messages(np.random.default_rng(20261201), COUNT)


def test_every_type_is_drawn(messages: np.ndarray):
    assert set(np.unique(messages['type']).tolist()) == set(TYPES.tolist())


def test_python_encoded_messages_decode_in_c_to_the_same_values(host_lib: FirmwareHost,
                                                                messages: np.ndarray):
    stream = b''.join(encode_frame(to_python(r), int(r['seq'])) for r in messages)
    decoded, stats = host_lib.decode_stream(stream)
    assert stats['frames_ok'] == COUNT and stats['resyncs'] == 0
    assert len(decoded) == COUNT
    rows = (decoded.view(np.uint8).reshape(COUNT, -1)
            != messages.view(np.uint8).reshape(COUNT, -1)).any(axis=1)
    mismatched = np.flatnonzero(rows)
    assert mismatched.size == 0, f'first mismatch: {decoded[mismatched[0]]} != ' \
                                 f'{messages[mismatched[0]]}'


def test_c_encoded_messages_decode_in_python_to_the_same_values(host_lib: FirmwareHost,
                                                                messages: np.ndarray):
    stream = host_lib.encode_stream(messages)
    decoder = StreamDecoder()
    frames = decoder.feed(stream)
    assert len(frames) == COUNT and decoder.stats.resyncs == 0
    decoded = np.zeros(COUNT, MSG_DTYPE)
    for i, frame in enumerate(frames):
        from_python(frame, decoded, i)
    rows = (decoded.view(np.uint8).reshape(COUNT, -1)
            != messages.view(np.uint8).reshape(COUNT, -1)).any(axis=1)
    mismatched = np.flatnonzero(rows)
    assert mismatched.size == 0, f'first mismatch: {decoded[mismatched[0]]} != ' \
                                 f'{messages[mismatched[0]]}'
