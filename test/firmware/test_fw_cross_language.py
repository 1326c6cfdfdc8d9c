# SPDX-License-Identifier: Apache-2.0
"""
Cross-language: 100,000 random valid messages through both codecs, both ways.

Encoded by wirefish_bridge.codec they decode in C to the same values, and encoded in C they
decode in Python to the same values; every field of every type of protocol version 2, floats
compared bit for bit (finite binary32 of every kind: normal, subnormal, +-0), integers of every
width at their extremes too.
"""

from firmware_host import FirmwareHost, MESSAGE_TYPES, random_messages, to_python, to_record
import numpy as np
import pytest
from wirefish_bridge.codec import encode_frame, StreamDecoder

COUNT = 100_000


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
    decoded = np.concatenate([to_record(frame.message, frame.seq) for frame in frames])
    rows = (decoded.view(np.uint8).reshape(COUNT, -1)
            != messages.view(np.uint8).reshape(COUNT, -1)).any(axis=1)
    mismatched = np.flatnonzero(rows)
    assert mismatched.size == 0, f'first mismatch: {decoded[mismatched[0]]} != ' \
                                 f'{messages[mismatched[0]]}'
