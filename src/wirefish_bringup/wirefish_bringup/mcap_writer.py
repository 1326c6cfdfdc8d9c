"""
A rosbag2 MCAP storage file written so that a killed writer loses at most one flush period.

Messages collect in an in-memory chunk; ``flush()`` writes the chunk (with its CRC) and its
message indexes to the file in one write and hands them to the kernel, so whatever was flushed
survives a SIGKILL of the process. ``close()`` adds the summary (schemas, channels, chunk
indexes, statistics) and the footer, as any MCAP writer does; a file that never got them is
made whole again by `wirefish bag reindex` (wirefish_bringup.reindex) from its intact chunks.

Schemas and channels go into the chunk they first appear in, so every chunk that survives
carries what is needed to read its messages.

Why not rosbags' writer: it keeps a chunk in memory until it holds 1 MiB (seconds to minutes of
the graph) and writes nothing else before close(). Why chunks rather than ~1 s split files: on
the graph's traffic a 0.5 s flush costs no measurable CPU and 0.3 % more bytes, where 1 s splits
repeat every schema and summary per file (+6 % bytes, 3,600 files an hour, and rosbags opens
every file of a bag at once).
"""

from collections import defaultdict
from io import BytesIO
from pathlib import Path

from wirefish_bringup import mcap_records as rec

PROFILE = 'ros2'
LIBRARY = 'wirefish_bringup'


class McapWriter:
    """Writes one MCAP file (ros2 profile, CDR messages, uncompressed chunks)."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._file = self.path.open('xb')  # never overwrite a recording
        self._schemas: dict[str, tuple[int, bytes]] = {}  # name -> (id, record)
        self._channels: list[bytes] = []
        self._chunk_indexes: list[rec.ChunkIndex] = []
        self.counts: dict[int, int] = {}  # messages per channel id, written or pending
        self.start_ns: int | None = None
        self.end_ns: int | None = None
        self._new_chunk()
        self._file.write(rec.MAGIC + rec.header(PROFILE, LIBRARY))
        self._file.flush()

    def _new_chunk(self) -> None:
        self._records = BytesIO()
        self._index: dict[int, list[tuple[int, int]]] = defaultdict(list)
        self._chunk_start_ns: int | None = None
        self._chunk_end_ns = 0

    def add_schema(self, name: str, encoding: str, data: str) -> int:
        """Return the id of the schema ``name``, adding it on first use."""
        if name not in self._schemas:
            schema_id = len(self._schemas) + 1
            self._schemas[name] = (schema_id, rec.schema(schema_id, name, encoding, data))
            self._records.write(self._schemas[name][1])
        return self._schemas[name][0]

    def add_channel(self, topic: str, schema_id: int, metadata: dict[str, str],
                    encoding: str = 'cdr') -> int:
        """Add a channel (a topic with its type and offered QoS); return its id."""
        channel_id = len(self._channels) + 1
        self._channels.append(rec.channel(channel_id, schema_id, topic, encoding, metadata))
        self._records.write(self._channels[-1])
        self.counts[channel_id] = 0
        return channel_id

    def write(self, channel_id: int, time_ns: int, data: bytes, sequence: int = 0) -> None:
        """Add one serialised message to the pending chunk."""
        if channel_id not in self.counts:
            raise ValueError(f'unknown channel id {channel_id}')
        self._index[channel_id].append((time_ns, self._records.tell()))
        self._records.write(rec.message(channel_id, sequence, time_ns, data))
        self.counts[channel_id] += 1
        if self._chunk_start_ns is None or time_ns < self._chunk_start_ns:
            self._chunk_start_ns = time_ns
        self._chunk_end_ns = max(self._chunk_end_ns, time_ns)
        self.start_ns = time_ns if self.start_ns is None else min(self.start_ns, time_ns)
        self.end_ns = time_ns if self.end_ns is None else max(self.end_ns, time_ns)

    def flush(self) -> None:
        """Write the pending chunk and its message indexes; nothing to do when it is empty."""
        records = self._records.getvalue()
        if not records:
            return
        start_ns = self._chunk_start_ns if self._chunk_start_ns is not None else 0
        chunk = rec.chunk(start_ns, self._chunk_end_ns, records)
        offset = self._file.tell()
        out = [chunk]
        index_offsets = {}
        position = offset + len(chunk)
        for channel_id, entries in self._index.items():
            index_offsets[channel_id] = position
            out.append(rec.message_index(channel_id, entries))
            position += len(out[-1])
        # One write, then to the kernel: a SIGKILL can no longer take it back.
        self._file.write(b''.join(out))
        self._file.flush()
        self._chunk_indexes.append(rec.ChunkIndex(
            start_ns, self._chunk_end_ns, offset, len(chunk), index_offsets,
            position - offset - len(chunk), len(records)))
        self._new_chunk()

    def close(self) -> None:
        """Flush, then write the summary and the footer: a complete, indexed MCAP file."""
        if self._file.closed:
            return
        self.flush()
        out = BytesIO()
        out.write(rec.data_end())
        summary_start = self._file.tell() + out.tell()
        groups = []
        for opcode, records in ((rec.SCHEMA, [r for _, r in self._schemas.values()]),
                                (rec.CHANNEL, self._channels),
                                (rec.CHUNK_INDEX, [c.encode() for c in self._chunk_indexes]),
                                (rec.STATISTICS, [rec.statistics(
                                    self.counts, len(self._schemas), len(self._chunk_indexes),
                                    self.start_ns or 0, self.end_ns or 0)])):
            if records:
                groups.append((opcode, self._file.tell() + out.tell(),
                               sum(len(r) for r in records)))
                out.write(b''.join(records))
        summary_offset_start = self._file.tell() + out.tell()
        for opcode, start, length in groups:
            out.write(rec.summary_offset(opcode, start, length))
        out.write(rec.footer(summary_start, summary_offset_start))
        self._file.write(out.getvalue())
        self._file.close()
