"""
Make a bag whose recorder was killed readable again, like `ros2 bag reindex`.

A killed recorder leaves its last MCAP file without summary and footer, and the bag without
metadata.yaml. Every chunk it flushed is still in the file, whole and with its CRC; what follows
the last whole chunk (a chunk cut short, garbage) is what was never flushed. Reindexing copies
the intact chunks, in order, into a new file that gets a summary and a footer, puts it in place
of the old one (an atomic rename: a reindex that is itself killed changes nothing), and writes
metadata.yaml from the summaries of all the bag's files. Finished files are left as they are.
"""

from collections.abc import Callable, Generator, Iterator
from dataclasses import dataclass
import mmap
import os
from pathlib import Path

from wirefish_bringup import mcap_records as rec
from wirefish_bringup.bag_storage import (IncompleteFile, read_file_info, storage_files,
                                          write_metadata)
from wirefish_bringup.mcap_writer import McapWriter


@dataclass(frozen=True)
class Recovery:
    """What rebuilding one file kept and what it had to leave out."""

    name: str
    chunks: int
    messages: int
    # Chunks framed whole whose content failed its CRC or could not be decoded (or compressed:
    # the recorder never compresses).
    damaged_chunks: int
    orphan_messages: int  # messages whose channel or type was defined in a damaged chunk
    dropped_tail_bytes: int  # from the end of the last whole record to the end of the file


Decoded = rec.SchemaRecord | rec.ChannelRecord | rec.MessageRecord
DECODERS: dict[int, Callable[[memoryview], Decoded]] = {
    rec.SCHEMA: rec.decode_schema, rec.CHANNEL: rec.decode_channel,
    rec.MESSAGE: rec.decode_message}


@dataclass
class _Scan:
    damaged_chunks: int = 0
    end: int = len(rec.MAGIC)  # offset just past the last whole record


def _decode_all(records: memoryview) -> list[Decoded]:
    return [DECODERS[opcode](content) for opcode, _, content in rec.iter_records(records)
            if opcode in DECODERS]


def _intact_chunks(data: memoryview, scan: _Scan) -> Generator[list[Decoded], None, None]:
    """
    Yield the decoded records of each intact chunk of an MCAP file's data, in file order.

    Records at the top level (some writers leave schemas, channels or messages unchunked) count
    as chunks of one record. A record cut short or an unknown opcode ends the data: nothing after
    it can be framed. A chunk whose framing is whole but whose content is damaged is skipped.
    """
    if bytes(data[:len(rec.MAGIC)]) != rec.MAGIC:
        raise rec.RecordError('not an MCAP file (no magic)')
    try:
        for opcode, offset, content in rec.iter_records(data, len(rec.MAGIC)):
            if opcode not in rec.KNOWN_OPCODES or opcode in (rec.DATA_END, rec.FOOTER):
                return
            scan.end = offset + rec.RECORD_PREFIX.size + len(content)
            if opcode == rec.CHUNK:
                try:
                    decoded = _decode_all(rec.decode_chunk(content))
                except rec.RecordError:
                    scan.damaged_chunks += 1
                    continue
                yield decoded
            elif opcode in DECODERS:
                yield _decode_all(data[offset:scan.end])
    except rec.RecordError:
        return  # a truncated tail: the data ends at the last whole record


def _copy(chunks: Iterator[list[Decoded]], writer: McapWriter) -> tuple[int, int, int]:
    """Write the chunks' records through ``writer``; return (chunks, messages, orphans)."""
    schema_ids: dict[int, int] = {}
    channel_ids: dict[int, int] = {}
    count = messages = orphans = 0
    for records in chunks:
        for record in records:
            if isinstance(record, rec.SchemaRecord):
                schema_ids[record.schema_id] = writer.add_schema(
                    record.name, record.encoding, record.data)
            elif isinstance(record, rec.ChannelRecord):
                if record.schema_id in schema_ids:  # else its type is lost: orphans follow
                    channel_ids[record.channel_id] = writer.add_channel(
                        record.topic, schema_ids[record.schema_id], record.metadata,
                        record.encoding)
            elif record.channel_id in channel_ids:
                writer.write(channel_ids[record.channel_id], record.log_time_ns, record.data,
                             record.sequence)
                messages += 1
            else:
                orphans += 1
        writer.flush()  # one chunk out per chunk in
        count += 1
    return count, messages, orphans


def rebuild(source: Path, target: Path) -> Recovery:
    """Write the intact chunks of ``source`` into a new, finished MCAP file ``target``."""
    scan = _Scan()
    writer = McapWriter(target)
    try:
        with Path(source).open('rb') as file:
            size = os.fstat(file.fileno()).st_size
            if size == 0:  # killed before its header was written: nothing to recover
                chunks = messages = orphans = 0
                scan.end = 0
            else:
                # Mapped, not read: a long recording need not fit in memory.
                with mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ) as data:
                    view = memoryview(data)
                    intact = _intact_chunks(view, scan)
                    try:
                        chunks, messages, orphans = _copy(intact, writer)
                    finally:
                        intact.close()  # drops its views of the map, so the map can close
                        view.release()
    finally:
        writer.close()
    return Recovery(Path(source).name, chunks, messages, scan.damaged_chunks, orphans,
                    size - scan.end)


def reindex(bag_dir: Path) -> list[Recovery]:
    """
    Rebuild every unfinished MCAP file of ``bag_dir`` and write its metadata.yaml.

    Returns what was recovered from each rebuilt file (finished files are not listed).
    Raises FileNotFoundError when the directory holds no MCAP file.
    """
    bag_dir = Path(bag_dir)
    files = storage_files(bag_dir)
    if not files:
        raise FileNotFoundError(f'{bag_dir}: no .mcap file, not a bag')
    recoveries = []
    for path in files:
        try:
            read_file_info(path)
            continue
        except IncompleteFile:
            pass
        tmp = path.with_name(path.name + '.reindex')
        tmp.unlink(missing_ok=True)  # left by a reindex that was itself interrupted
        try:
            recoveries.append(rebuild(path, tmp))
        except rec.RecordError as error:
            tmp.unlink(missing_ok=True)
            raise IncompleteFile(f'{path}: cannot be recovered: {error}') from error
        os.replace(tmp, path)
    write_metadata(bag_dir)
    return recoveries
