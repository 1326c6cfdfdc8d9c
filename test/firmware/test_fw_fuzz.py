# SPDX-License-Identifier: Apache-2.0
"""
Fuzz: 1,000,000 random and mutated inputs to the C decoder built with ASan and UBSan.

Each input goes to the sanitized driver (firmware/test/fuzz_decoder.c: its decoder and a
whole board) and to wirefish_bridge's StreamDecoder, both framed 0x00 input 0x00 and both one
decoder for the whole run. The claim holds for every input counted: the driver exits cleanly
with no sanitizer report, and for each input the two decoders accept the same frames (the
same canonical bodies, in order: none accepted by one and dropped by the other) and end with
the same counters of every kind of drop.
"""

import binascii
import os
import struct
import subprocess

from cobs import cobs
from firmware_host import FUZZ_DRIVER, random_messages, STATS_FIELDS, to_python
import numpy as np
from wirefish_bridge.codec import encode_body, encode_frame, StreamDecoder
from wirefish_bridge.protocol import MsgType, PAYLOAD_SIZES

COUNT = 1_000_000
BATCH = 20_000
POOL = 4096
KNOWN_SIZES = {int(kind): size for kind, size in PAYLOAD_SIZES.items()}
KINDS = sorted(KNOWN_SIZES)
# Where a type's binary32 fields start in its payload (4-byte steps from there).
FLOATS_AT = {MsgType.SERVO_CMD: 0, MsgType.GAIT: 2, MsgType.TELEMETRY: 4, MsgType.SERVO_TRIM: 4,
             MsgType.SERVO_TRIM_REPORT: 4}
NON_FINITE = (b'\x00\x00\x80\x7f', b'\x00\x00\x80\xff', b'\x00\x00\xc0\x7f', b'\x01\x00\x80\xff')


def valid_pool(rng: np.random.Generator) -> list[bytes]:
    """Return POOL valid frames (wire bytes) of random messages, encoded by the Python codec."""
    return [encode_frame(to_python(r), int(r['seq'])) for r in random_messages(rng, POOL)]


def crafted(draw: list[int], rng_bytes: bytes) -> bytes:
    """Return a run whose CRC is right: any type, a payload size near the type's, odd values."""
    kind = KINDS[draw[1] % len(KINDS)] if draw[1] % 10 else draw[0] % 256
    size = KNOWN_SIZES.get(kind, draw[2] % 66)
    size = (size, size, size - 1, size + 1, draw[2] % 72)[draw[3] % 5]
    payload = bytearray(rng_bytes[:max(size, 0)].ljust(max(size, 0), b'\x01'))
    if payload and draw[4] % 3 == 0:
        base = FLOATS_AT.get(kind, 0)
        at = base + (draw[5] % max(1, (len(payload) - base) // 4)) * 4
        payload[at:at + 4] = NON_FINITE[draw[6] % 4][:max(0, len(payload) - at)]
    if kind == 0x01 and len(payload) > 1:
        payload[1] = draw[7] % 4  # roles 0 and 1 are known, 2 and 3 not
    body = struct.pack('<BH', kind, draw[8]) + bytes(payload)
    body += struct.pack('<H', binascii.crc_hqx(body, 0xFFFF))
    return cobs.encode(body)


def mutated(frame: bytes, draw: list[int], other: bytes) -> bytes:
    """Return ``frame`` after 1 to 4 edits: bit flip, byte set, insert, delete, cut, splice."""
    data = bytearray(frame)
    for k in range(1 + draw[0] % 4):
        op, at, value = draw[1 + 3 * k] % 6, draw[2 + 3 * k], draw[3 + 3 * k]
        at %= max(1, len(data))
        if op == 0 and data:
            data[at] ^= 1 << (value % 8)
        elif op == 1 and data:
            data[at] = (0, 1, 0xFF, value % 256)[value % 4]
        elif op == 2:
            data.insert(at, value % 256)
        elif op == 3 and data:
            del data[at]
        elif op == 4:
            del data[at:]
        else:
            data[at:at] = other[value % len(other):]
    return bytes(data)


def inputs(rng: np.random.Generator, pool: list[bytes], count: int) -> list[bytes]:
    """Return ``count`` inputs: valid frames, mutated ones, crafted runs and random bytes."""
    draws = rng.integers(0, 1 << 16, (count, 16)).tolist()
    noise = rng.integers(0, 256, count * 80, dtype=np.uint8).tobytes()
    out = []
    for i, draw in enumerate(draws):
        kind = draw[15] % 20
        frame = pool[draw[14] % POOL]
        if kind < 3:    # 15 %: one or two valid frames
            out.append(frame + pool[draw[13] % POOL] if kind == 0 else frame)
        elif kind < 11:  # 40 %: a valid frame, damaged
            out.append(mutated(frame, draw, pool[draw[12] % POOL]))
        elif kind < 16:  # 25 %: a run with a right CRC and odd contents
            out.append(b'\x00' + crafted(draw, noise[80 * i:80 * i + 80]) + b'\x00')
        else:           # 20 %: random bytes, 0 to 100 of them, often with zeros
            length = draw[0] % 101
            chunk = noise[80 * i:80 * i + min(length, 80)] * 2
            out.append(chunk[:length].replace(b'\x07', b'\x00'))
    return out


def python_verdicts(decoder: StreamDecoder, batch: list[bytes]) -> bytes:
    """Return what the driver writes per input, from the Python decoder."""
    out = bytearray()
    for data in batch:
        frames = decoder.feed(b'\x00' + data + b'\x00')
        out += struct.pack('<H', len(frames))
        for frame in frames:
            body = encode_body(frame.message, frame.seq)
            out.append(len(body))
            out += body
    return bytes(out)


def first_difference(c_out: bytes, py_out: bytes, corpus: list[bytes]) -> str:
    """Describe the first input on which the two decoders disagree."""
    ci = pi = 0
    for index, data in enumerate(corpus):
        c_next, p_next = _skip(c_out, ci), _skip(py_out, pi)
        if c_out[ci:c_next] != py_out[pi:p_next]:
            return (f'input {index} ({data.hex()}): C {c_out[ci:c_next].hex()} vs Python '
                    f'{py_out[pi:p_next].hex()}')
        ci, pi = c_next, p_next
    return 'the counters differ'


def _skip(stream: bytes, at: int) -> int:
    count = struct.unpack_from('<H', stream, at)[0]
    at += 2
    for _ in range(count):
        at += 1 + stream[at]
    return at


def test_c_decoder_and_python_decoder_agree_on_a_million_inputs_under_sanitizers(tmp_path):
    rng = np.random.default_rng(22)
    pool = valid_pool(rng)
    out_path = tmp_path / 'c_verdicts.bin'
    env = dict(os.environ, ASAN_OPTIONS='detect_leaks=1:abort_on_error=0:exitcode=86',
               UBSAN_OPTIONS='print_stacktrace=1:halt_on_error=1:exitcode=87')
    driver = subprocess.Popen([str(FUZZ_DRIVER), '/dev/stdin', str(out_path)],
                              stdin=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    decoder = StreamDecoder()
    expected = bytearray()
    corpus: list[bytes] = []
    try:
        for _ in range(COUNT // BATCH):
            batch = inputs(rng, pool, BATCH)
            corpus += batch
            assert driver.stdin is not None
            driver.stdin.write(b''.join(struct.pack('<I', len(d)) + d for d in batch))
            expected += python_verdicts(decoder, batch)
        driver.stdin.close()
        stderr = driver.stderr.read() if driver.stderr else b''
        assert driver.wait(timeout=120) == 0, stderr.decode(errors='replace')
    finally:
        if driver.poll() is None:
            driver.kill()
            driver.wait()
    assert stderr == b'', stderr.decode(errors='replace')  # no sanitizer report of any kind
    c_out = out_path.read_bytes()
    c_verdicts, c_counters = c_out[:-48], struct.unpack('<12I', c_out[-48:])
    py_counters = tuple(decoder.stats.as_dict()[name] for name in STATS_FIELDS)
    assert len(corpus) == COUNT
    assert c_verdicts == bytes(expected), first_difference(c_verdicts, bytes(expected), corpus)
    assert c_counters == py_counters, dict(zip(STATS_FIELDS, zip(c_counters, py_counters)))
    counters = dict(zip(STATS_FIELDS, c_counters))
    # Every path was taken: acceptances and each kind of drop, many times.
    assert counters['frames_ok'] > 100_000
    assert min(counters[name] for name in STATS_FIELDS[2:9]) > 1000, counters
    print(f'fuzz: {COUNT} inputs, {counters["bytes_in"]} bytes, C and Python agree; '
          f'{counters}')
