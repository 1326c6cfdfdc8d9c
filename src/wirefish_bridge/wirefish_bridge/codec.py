# SPDX-License-Identifier: Apache-2.0
"""
Framing of the wirefish serial protocol: COBS + 0x00 delimiter, CRC-16/CCITT-FALSE.

Pure (no I/O, no rclpy). On the wire a frame is ``0x00 COBS(body) 0x00`` with
``body = type (u8) | seq (u16 LE) | payload | crc (u16 LE)`` and the CRC-16/CCITT-FALSE
(poly 0x1021, init 0xFFFF, no reflection, no final xor; ``binascii.crc_hqx``) over everything
before it. COBS removes every 0x00 from the body, so 0x00 only ever delimits frames and the
decoder resynchronises on the next one after any damage. The leading 0x00 (an empty run, which
receivers ignore) ends any garbage before the frame, so the frame after garbage is not lost.

``StreamDecoder`` takes arbitrary chunks (split frames, several frames, garbage, flipped bits),
returns the valid messages, counts each kind of error and never raises on input bytes; it holds
at most ``MAX_ENCODED_FRAME`` bytes.
"""

from __future__ import annotations

import binascii
from dataclasses import dataclass, fields
import struct

from cobs import cobs

from wirefish_bridge.protocol import (Message, message_type, MsgType, pack_payload,
                                      PAYLOAD_SIZES, unpack_payload)

DELIMITER = b'\x00'
_HEADER = struct.Struct('<BH')
_CRC = struct.Struct('<H')
MIN_BODY = _HEADER.size + _CRC.size
MAX_BODY = MIN_BODY + max(PAYLOAD_SIZES.values())
# COBS adds one byte per 254 (and one); anything longer than this cannot be a frame.
MAX_ENCODED_FRAME = MAX_BODY + MAX_BODY // 254 + 1
SEQ_MODULO = 1 << 16


def crc16(data: bytes) -> int:
    """Return the CRC-16/CCITT-FALSE of ``data`` (check value of b'123456789': 0x29B1)."""
    return binascii.crc_hqx(data, 0xFFFF)


def encode_body(message: Message, seq: int) -> bytes:
    """Return the unstuffed frame body of ``message`` with sequence number ``seq`` (mod 2^16)."""
    body = _HEADER.pack(int(message_type(message)), seq % SEQ_MODULO) + pack_payload(message)
    return body + _CRC.pack(crc16(body))


def encode_frame(message: Message, seq: int) -> bytes:
    """Return the bytes on the wire of ``message`` with sequence ``seq``: 0x00 COBS(body) 0x00."""
    return DELIMITER + cobs.encode(encode_body(message, seq)) + DELIMITER


class FrameEncoder:
    """Encodes messages with a running sequence number (one per sender, all types)."""

    def __init__(self, first_seq: int = 0) -> None:
        """Start counting at ``first_seq``."""
        self.next_seq = first_seq % SEQ_MODULO

    def encode(self, message: Message) -> bytes:
        """Return the wire bytes of ``message`` and advance the sequence number."""
        frame = encode_frame(message, self.next_seq)
        self.next_seq = (self.next_seq + 1) % SEQ_MODULO
        return frame


@dataclass(frozen=True)
class DecodedFrame:
    """A frame that passed every check: its type, sequence number and message."""

    kind: MsgType
    seq: int
    message: Message


@dataclass
class DecoderStats:
    """
    Counters of a ``StreamDecoder`` (monotonic).

    Every rejected byte run counts once in ``resyncs`` and once in exactly one of
    ``cobs_errors``, ``short_frames``, ``crc_errors``, ``unknown_type``, ``length_errors``,
    ``invalid_payload`` or ``overflows``. ``seq_gaps`` counts frames the peer numbered but that
    never arrived valid (lost, or rejected here); ``seq_resets`` jumps of 2^15 or more (the
    peer restarted).
    """

    bytes_in: int = 0
    frames_ok: int = 0
    cobs_errors: int = 0
    short_frames: int = 0
    crc_errors: int = 0
    unknown_type: int = 0
    length_errors: int = 0
    invalid_payload: int = 0
    overflows: int = 0
    resyncs: int = 0
    seq_gaps: int = 0
    seq_resets: int = 0

    def as_dict(self) -> dict[str, int]:
        """Return the counters by name."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def check_body(body: bytes) -> tuple[str, DecodedFrame | None]:
    """
    Return ('ok', frame) for a valid unstuffed body, else (name of the failed check, None).

    The checks, in order: length >= 5 ('short_frames'), CRC ('crc_errors'), known type
    ('unknown_type'), payload size of that type ('length_errors'), values ('invalid_payload').
    """
    if len(body) < MIN_BODY:
        return 'short_frames', None
    if crc16(body[:-_CRC.size]) != _CRC.unpack_from(body, len(body) - _CRC.size)[0]:
        return 'crc_errors', None
    kind, seq = _HEADER.unpack_from(body)
    try:
        kind = MsgType(kind)
    except ValueError:
        return 'unknown_type', None
    payload = body[_HEADER.size:-_CRC.size]
    if len(payload) != PAYLOAD_SIZES[kind]:
        return 'length_errors', None
    message = unpack_payload(kind, payload)
    if message is None:
        return 'invalid_payload', None
    return 'ok', DecodedFrame(kind, seq, message)


class StreamDecoder:
    """Streaming frame decoder: feed it any chunks, get the valid frames back."""

    def __init__(self) -> None:
        """Start with an empty buffer, synchronised (the first 0x00 ends the first frame)."""
        self.stats = DecoderStats()
        self._buffer = bytearray()
        self._discarding = False   # an over-long run is being skipped up to the next 0x00
        self._last_seq: int | None = None

    @property
    def buffered(self) -> int:
        """Return how many bytes of an unfinished frame are held (<= MAX_ENCODED_FRAME)."""
        return len(self._buffer)

    def feed(self, data: bytes) -> list[DecodedFrame]:
        """Return the valid frames completed by ``data`` (any bytes; never raises)."""
        frames: list[DecodedFrame] = []
        self.stats.bytes_in += len(data)
        for index, part in enumerate(bytes(data).split(DELIMITER)):
            if index:
                self._end_of_frame(frames)
            self._append(part)
        return frames

    def _append(self, part: bytes) -> None:
        if self._discarding or not part:
            return
        if len(self._buffer) + len(part) > MAX_ENCODED_FRAME:
            # Longer than any frame: a lost delimiter. Skip to the next one, keep memory bounded.
            self._reject('overflows')
            self._buffer.clear()
            self._discarding = True
            return
        self._buffer += part

    def _end_of_frame(self, frames: list[DecodedFrame]) -> None:
        if self._discarding:
            self._discarding = False
            return
        if not self._buffer:
            return  # back-to-back delimiters are idle fill, not an error
        encoded = bytes(self._buffer)
        self._buffer.clear()
        try:
            body = cobs.decode(encoded)
        except cobs.DecodeError:
            self._reject('cobs_errors')
            return
        verdict, frame = check_body(body)
        if frame is None:
            self._reject(verdict)
            return
        self._count_sequence(frame.seq)
        self.stats.frames_ok += 1
        frames.append(frame)

    def _reject(self, counter: str) -> None:
        setattr(self.stats, counter, getattr(self.stats, counter) + 1)
        self.stats.resyncs += 1

    def _count_sequence(self, seq: int) -> None:
        if self._last_seq is not None:
            gap = (seq - self._last_seq - 1) % SEQ_MODULO
            if gap >= SEQ_MODULO // 2:
                self.stats.seq_resets += 1
            else:
                self.stats.seq_gaps += gap
        self._last_seq = seq

    def reset_sequence(self) -> None:
        """Forget the peer's last sequence number (after a reconnect) and any partial frame."""
        self._last_seq = None
        self._buffer.clear()
        self._discarding = True  # the first bytes after a reopen may start mid-frame
