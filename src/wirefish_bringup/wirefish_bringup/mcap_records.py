"""
MCAP records, encoded and decoded (https://mcap.dev/spec): the few the bags use.

Pure functions over bytes. Every record is ``opcode u8, length u64, content``; integers are little
endian, strings and byte arrays carry a u32 length, maps a u32 byte length.
"""

from binascii import crc32
from collections.abc import Iterator
from dataclasses import dataclass
import struct

MAGIC = b'\x89MCAP0\r\n'
HEADER = 0x01
FOOTER = 0x02
SCHEMA = 0x03
CHANNEL = 0x04
MESSAGE = 0x05
CHUNK = 0x06
MESSAGE_INDEX = 0x07
CHUNK_INDEX = 0x08
ATTACHMENT = 0x09
ATTACHMENT_INDEX = 0x0A
STATISTICS = 0x0B
METADATA = 0x0C
METADATA_INDEX = 0x0D
SUMMARY_OFFSET = 0x0E
DATA_END = 0x0F
KNOWN_OPCODES = frozenset(range(HEADER, DATA_END + 1))
RECORD_PREFIX = struct.Struct('<BQ')
FOOTER_SIZE = RECORD_PREFIX.size + 20 + len(MAGIC)  # footer record, then the closing magic


class RecordError(ValueError):
    """Bytes that are not the record they should be (truncated, corrupt or unknown)."""


def record(opcode: int, content: bytes) -> bytes:
    """Return one record: opcode, content length, content."""
    return RECORD_PREFIX.pack(opcode, len(content)) + content


def _string(text: str) -> bytes:
    data = text.encode()
    return struct.pack('<I', len(data)) + data


def _string_map(items: dict[str, str]) -> bytes:
    body = b''.join(_string(k) + _string(v) for k, v in items.items())
    return struct.pack('<I', len(body)) + body


def header(profile: str, library: str) -> bytes:
    """Return a Header record."""
    return record(HEADER, _string(profile) + _string(library))


def schema(schema_id: int, name: str, encoding: str, data: str) -> bytes:
    """Return a Schema record (``data``: the message definition text)."""
    raw = data.encode()
    return record(SCHEMA, struct.pack('<H', schema_id) + _string(name) + _string(encoding)
                  + struct.pack('<I', len(raw)) + raw)


def channel(channel_id: int, schema_id: int, topic: str, encoding: str,
            metadata: dict[str, str]) -> bytes:
    """Return a Channel record."""
    return record(CHANNEL, struct.pack('<HH', channel_id, schema_id) + _string(topic)
                  + _string(encoding) + _string_map(metadata))


MESSAGE_HEAD = struct.Struct('<HIQQ')  # channel id, sequence, log time, publish time


def message(channel_id: int, sequence: int, log_time_ns: int, data: bytes) -> bytes:
    """Return a Message record (log and publish time both ``log_time_ns``)."""
    return record(MESSAGE, MESSAGE_HEAD.pack(channel_id, sequence % 2**32, log_time_ns,
                                             log_time_ns) + data)


CHUNK_HEAD = struct.Struct('<QQQI')  # start time, end time, uncompressed size, uncompressed crc


def chunk(start_ns: int, end_ns: int, records: bytes) -> bytes:
    """Return an uncompressed Chunk record of ``records``, with their CRC32."""
    return record(CHUNK, CHUNK_HEAD.pack(start_ns, end_ns, len(records), crc32(records))
                  + _string('') + struct.pack('<Q', len(records)) + records)


def message_index(channel_id: int, entries: list[tuple[int, int]]) -> bytes:
    """Return a Message Index record: (log time, offset in the chunk's records) per message."""
    body = b''.join(struct.pack('<QQ', t, offset) for t, offset in entries)
    return record(MESSAGE_INDEX, struct.pack('<HI', channel_id, len(body)) + body)


@dataclass(frozen=True)
class ChunkIndex:
    """Where one chunk and its message indexes are in the file."""

    start_ns: int
    end_ns: int
    chunk_offset: int
    chunk_length: int
    message_index_offsets: dict[int, int]
    message_index_length: int
    records_size: int

    def encode(self) -> bytes:
        """Return the Chunk Index record."""
        offsets = b''.join(struct.pack('<HQ', cid, offset)
                           for cid, offset in self.message_index_offsets.items())
        return record(CHUNK_INDEX, struct.pack(
            '<QQQQ', self.start_ns, self.end_ns, self.chunk_offset, self.chunk_length)
            + struct.pack('<I', len(offsets)) + offsets
            + struct.pack('<Q', self.message_index_length) + _string('')
            + struct.pack('<QQ', self.records_size, self.records_size))


def statistics(counts: dict[int, int], schema_count: int, chunk_count: int,
               start_ns: int, end_ns: int) -> bytes:
    """Return a Statistics record; ``counts``: messages per channel id."""
    per_channel = b''.join(struct.pack('<HQ', cid, n) for cid, n in sorted(counts.items()))
    return record(STATISTICS, struct.pack(
        '<QHIIIIQQ', sum(counts.values()), schema_count, len(counts), 0, 0, chunk_count,
        start_ns, end_ns) + struct.pack('<I', len(per_channel)) + per_channel)


def summary_offset(opcode: int, start: int, length: int) -> bytes:
    """Return a Summary Offset record: where the group of ``opcode`` records is."""
    return record(SUMMARY_OFFSET, struct.pack('<BQQ', opcode, start, length))


def data_end() -> bytes:
    """Return a Data End record (no data-section CRC)."""
    return record(DATA_END, struct.pack('<I', 0))


def footer(summary_start: int, summary_offset_start: int) -> bytes:
    """Return the Footer record and the closing magic."""
    return record(FOOTER, struct.pack('<QQI', summary_start, summary_offset_start, 0)) + MAGIC


# Decoding ------------------------------------------------------------------------------------

def iter_records(data: bytes | memoryview, start: int = 0,
                 end: int | None = None) -> Iterator[tuple[int, int, memoryview]]:
    """
    Yield (opcode, offset, content) for each record of ``data[start:end]``.

    Raises RecordError at the first record that does not fit in the bytes (a truncated tail).
    """
    view = memoryview(data)
    end = len(view) if end is None else end
    pos = start
    while pos < end:
        if pos + RECORD_PREFIX.size > end:
            raise RecordError(f'truncated record prefix at offset {pos}')
        opcode, length = RECORD_PREFIX.unpack_from(view, pos)
        content_start = pos + RECORD_PREFIX.size
        if length > end - content_start:
            raise RecordError(f'record at offset {pos} runs past the end ({length} bytes)')
        yield opcode, pos, view[content_start:content_start + length]
        pos = content_start + length


class _Cursor:
    """Reads fields off a record's content; any overrun is a RecordError."""

    def __init__(self, content: memoryview) -> None:
        self._view = content
        self._pos = 0

    def unpack(self, fmt: str) -> tuple:
        size = struct.calcsize(fmt)
        if self._pos + size > len(self._view):
            raise RecordError('record content shorter than its fields')
        values = struct.unpack_from(fmt, self._view, self._pos)
        self._pos += size
        return values

    def take(self, size: int) -> memoryview:
        if self._pos + size > len(self._view):
            raise RecordError('record field runs past its record')
        part = self._view[self._pos:self._pos + size]
        self._pos += size
        return part

    def string(self) -> str:
        (size,) = self.unpack('<I')
        try:
            return bytes(self.take(size)).decode()
        except UnicodeDecodeError as error:
            raise RecordError('string field is not UTF-8') from error

    def string_map(self) -> dict[str, str]:
        (size,) = self.unpack('<I')
        inner = _Cursor(self.take(size))
        items = {}
        while inner._pos < size:
            key = inner.string()
            items[key] = inner.string()
        return items

    def rest(self) -> memoryview:
        return self.take(len(self._view) - self._pos)


@dataclass(frozen=True)
class SchemaRecord:
    """A decoded Schema record."""

    schema_id: int
    name: str
    encoding: str
    data: str


@dataclass(frozen=True)
class ChannelRecord:
    """A decoded Channel record."""

    channel_id: int
    schema_id: int
    topic: str
    encoding: str
    metadata: dict[str, str]


@dataclass(frozen=True)
class MessageRecord:
    """A decoded Message record."""

    channel_id: int
    sequence: int
    log_time_ns: int
    data: bytes


def decode_schema(content: memoryview) -> SchemaRecord:
    """Decode a Schema record's content."""
    cursor = _Cursor(content)
    (schema_id,) = cursor.unpack('<H')
    name, encoding = cursor.string(), cursor.string()
    return SchemaRecord(schema_id, name, encoding, cursor.string())


def decode_channel(content: memoryview) -> ChannelRecord:
    """Decode a Channel record's content."""
    cursor = _Cursor(content)
    channel_id, schema_id = cursor.unpack('<HH')
    topic, encoding = cursor.string(), cursor.string()
    return ChannelRecord(channel_id, schema_id, topic, encoding, cursor.string_map())


def decode_message(content: memoryview) -> MessageRecord:
    """Decode a Message record's content."""
    cursor = _Cursor(content)
    channel_id, sequence, log_time, _ = cursor.unpack(MESSAGE_HEAD.format)
    return MessageRecord(channel_id, sequence, log_time, bytes(cursor.rest()))


def decode_chunk(content: memoryview) -> memoryview:
    """
    Return a Chunk record's inner records, checked against its size and CRC.

    Raises RecordError for a compressed chunk (the bags never compress) or damaged records.
    """
    cursor = _Cursor(content)
    _, _, size, crc = cursor.unpack(CHUNK_HEAD.format)
    compression = cursor.string()
    if compression:
        raise RecordError(f'chunk compressed with {compression!r}: not supported')
    (stored,) = cursor.unpack('<Q')
    records = cursor.take(stored)
    if stored != size or (crc and crc32(records) != crc):
        raise RecordError('chunk size or CRC does not match its records')
    return records


def decode_statistics(content: memoryview) -> tuple[dict[int, int], int, int]:
    """Return (messages per channel id, start ns, end ns) of a Statistics record."""
    cursor = _Cursor(content)
    _, _, _, _, _, _, start_ns, end_ns = cursor.unpack('<QHIIIIQQ')
    (size,) = cursor.unpack('<I')
    inner = _Cursor(cursor.take(size))
    counts = dict(inner.unpack('<HQ') for _ in range(size // 10))
    return counts, start_ns, end_ns


def decode_footer(tail: bytes) -> tuple[int, int]:
    """Return (summary start, summary offset start) from a file's last FOOTER_SIZE bytes."""
    if len(tail) != FOOTER_SIZE or tail[-len(MAGIC):] != MAGIC:
        raise RecordError('no closing magic: the file was not finished')
    opcode, length = RECORD_PREFIX.unpack_from(tail)
    if opcode != FOOTER or length != 20:
        raise RecordError('no footer record before the closing magic')
    summary_start, summary_offset_start, _ = struct.unpack_from('<QQI', tail,
                                                                RECORD_PREFIX.size)
    return summary_start, summary_offset_start
