# SPDX-License-Identifier: Apache-2.0
"""Fuzz: 100,000 random and mutated frames in one stream, fed in random chunks."""

from dataclasses import fields

import numpy as np
from wirefish_bridge.codec import DecoderStats, FrameEncoder, MAX_ENCODED_FRAME, StreamDecoder
from wirefish_bridge.protocol import (Ack, ErrorReport, Gait, Health, Heartbeat, LinkConfig, Role,
                                      ServoCommand, Telemetry, TelemetryCompact)

FRAMES = 100_000
SEED = 20260522


def _random_message(rng: np.random.Generator):
    """Return a random valid message of any type of protocol version 2."""
    floats = rng.normal(0.0, 3.0, 12).astype(np.float32).astype(float).tolist()
    ints = rng.integers(0, 2**32, 20, dtype=np.uint64).tolist()
    i16 = rng.integers(-2**15, 2**15, 11).tolist()
    kind = rng.integers(9)
    if kind == 0:
        return Heartbeat(int(rng.integers(256)), Role(int(rng.integers(2))),
                         int(rng.integers(2**32)))
    if kind == 1:
        return ServoCommand(floats[0], floats[1])
    if kind == 2:
        return Telemetry(int(rng.integers(2**32)), *floats[:3], tuple(floats[3:6]),
                         tuple(floats[6:9]), *floats[9:12], int(rng.integers(2**16)),
                         int(rng.integers(2**16)))
    if kind == 3:
        return LinkConfig(ints[0] % 2**16, ints[1] % 256, *(v % 2**16 for v in ints[2:5]))
    if kind == 4:
        return Ack(ints[0] % 256, ints[1] % 2**16, ints[2] % 256)
    if kind == 5:
        return Gait(ints[0] % 2**16, *floats[:10])
    if kind == 6:
        return TelemetryCompact(ints[0], *i16[:3], tuple(i16[3:6]), tuple(i16[6:9]), *i16[9:11],
                                *(v % 2**16 for v in ints[1:4]))
    if kind == 7:
        return Health(*(v % 256 for v in ints[:3]), *ints[3:8], *(v % 2**16 for v in ints[8:10]),
                      *ints[10:17], *(v % 2**16 for v in ints[17:20]))
    return ErrorReport(int(rng.integers(256)), int(rng.integers(2**16)))


def _mutate(frame: bytes, rng: np.random.Generator) -> bytes:
    data = bytearray(frame)
    how = rng.integers(4)
    if how == 0:        # one to three flipped bits anywhere (delimiters included)
        for _ in range(rng.integers(1, 4)):
            data[rng.integers(len(data))] ^= 1 << int(rng.integers(8))
    elif how == 1:      # one byte replaced
        index = rng.integers(len(data))
        data[index] = (data[index] + int(rng.integers(1, 256))) % 256
    elif how == 2:      # truncated
        del data[rng.integers(1, len(data) - 1):]
    else:               # one byte inserted
        data.insert(int(rng.integers(1, len(data))), int(rng.integers(256)))
    return bytes(data)


def _build_stream(rng: np.random.Generator) -> tuple[bytes, dict[bytes, tuple], int]:
    """Return the stream, every generated frame by its stuffed bytes, and how many are intact."""
    encoder = FrameEncoder()
    parts, generated, intact = [], {}, 0
    for _ in range(FRAMES):
        choice = rng.random()
        if choice < 0.1:   # garbage run, any bytes (zeros included), sometimes over-long
            length = int(rng.integers(1, 400 if rng.random() < 0.1 else 60))
            parts.append(rng.integers(0, 256, length, dtype=np.uint8).tobytes())
            continue
        message = _random_message(rng)
        seq = encoder.next_seq
        frame = encoder.encode(message)
        generated[frame.strip(b'\x00')] = (message, seq)
        if choice < 0.55:
            parts.append(frame)
            intact += 1
        else:
            parts.append(_mutate(frame, rng))
    return b''.join(parts), generated, intact


def _oracle(stream: bytes, generated: dict[bytes, tuple]) -> tuple[list, int, int]:
    """
    Independent oracle: split on 0x00; a run is a frame iff it is byte-identical to one sent.

    Return the (message, seq) list the decoder must yield, the number of runs it must reject
    as damaged and the number of over-long runs. (A mutation that only touched a delimiter
    leaves its frame intact: the oracle expects it, as it must.)
    """
    expected, bad, overflow = [], 0, 0
    for run in stream.split(b'\x00'):
        if not run:
            continue
        if len(run) > MAX_ENCODED_FRAME:
            overflow += 1
        elif run in generated:
            expected.append(generated[run])
        else:
            bad += 1
    return expected, bad, overflow


def _expected_gaps(expected: list) -> int:
    seqs = [seq for _, seq in expected]
    return sum((b - a - 1) % 65536 for a, b in zip(seqs, seqs[1:]))


def test_fuzzed_stream_yields_exactly_the_intact_frames_and_counts_the_rest():
    rng = np.random.default_rng(SEED)
    stream, generated, intact = _build_stream(rng)
    decoder = StreamDecoder()
    received = []
    position = 0
    while position < len(stream):   # random chunk sizes, 1 to 300 bytes
        size = int(rng.integers(1, 301))
        received += decoder.feed(stream[position:position + size])
        position += size

    expected, bad, overflow = _oracle(stream, generated)
    assert [(f.message, f.seq) for f in received] == expected  # nothing damaged accepted
    assert len(expected) >= intact                              # every intact frame received
    stats = decoder.stats
    assert stats.frames_ok == len(expected)
    assert stats.overflows == overflow
    assert stats.resyncs == bad + overflow
    errors = sum(getattr(stats, f.name) for f in fields(DecoderStats)
                 if f.name not in ('bytes_in', 'frames_ok', 'resyncs', 'seq_gaps', 'seq_resets'))
    assert errors == stats.resyncs
    assert stats.bytes_in == len(stream)
    assert (stats.seq_gaps, stats.seq_resets) == (_expected_gaps(expected), 0)
    assert min(stats.crc_errors, stats.cobs_errors, stats.short_frames) > 0
