"""
Cross-language: 100,000 random valid messages through both codecs, both ways.

Encoded by wirefish_bridge.codec they decode in C to the same values, and encoded in C they
decode in Python to the same values; every field of every type, floats compared bit for bit
(finite binary32 of every kind: normal, subnormal, +-0).
"""

from firmware_host import FirmwareHost, MESSAGE_TYPES, MSG_DTYPE, random_messages, to_python
import numpy as np
import pytest
from wirefish_bridge.codec import encode_frame, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Telemetry

COUNT = 100_000


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
    assert set(np.unique(messages['type']).tolist()) == set(MESSAGE_TYPES.tolist())


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
