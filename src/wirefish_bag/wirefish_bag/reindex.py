# SPDX-License-Identifier: Apache-2.0
"""
Make a bag whose recorder was killed readable again, like `ros2 bag reindex`.

A killed recorder leaves its last MCAP file without summary and footer, and the bag without
metadata.yaml. Every chunk it flushed is still in the file, whole and with its CRC; what follows
the last whole chunk (a chunk cut short, garbage) is what was never flushed. Reindexing copies
the intact chunks, in order, into a new file that gets a summary and a footer, puts it in place
of the old one (an atomic rename: a reindex that is itself killed changes nothing), and writes
metadata.yaml from the summaries of all the bag's files. Finished files are left as they are.
"""

from collections.abc import Iterator
from dataclasses import dataclass
import os
from pathlib import Path

from mcap.records import Channel, Chunk, DataEnd, Footer, Message, Schema
from mcap.stream_reader import breakup_chunk, StreamReader

from wirefish_bag.bag_storage import (IncompleteFile, MAGIC, READ_ERRORS, read_file_info,
                                      storage_files, write_metadata)
from wirefish_bag.bag_writer import BagFileWriter


@dataclass(frozen=True)
class Recovery:
    """What rebuilding one file kept and what it had to leave out."""

    name: str
    chunks: int
    messages: int
    # Chunks framed whole whose content failed its CRC or could not be decoded.
    damaged_chunks: int
    orphan_messages: int  # messages whose channel or type was defined in a damaged chunk
    dropped_tail_bytes: int  # from the end of the last whole record to the end of the file


Decoded = Schema | Channel | Message


@dataclass
class _Scan:
    damaged_chunks: int = 0
    end: int = len(MAGIC)  # offset just past the last whole record


def _intact_chunks(file, size: int, scan: _Scan) -> Iterator[list[Decoded]]:
    """
    Yield the records of each intact chunk of an MCAP file, in file order (mcap's reader).

    Records at the top level (some writers leave schemas, channels or messages unchunked) count
    as chunks of one record. A record cut short, or one longer than the rest of the file, ends
    the data: nothing after it can be framed. A chunk whose framing is whole but whose content
    fails its CRC or cannot be decoded is skipped.
    """
    reader = StreamReader(file, emit_chunks=True, record_size_limit=size)
    try:
        for record in reader.records:
            if isinstance(record, (DataEnd, Footer)):
                return
            scan.end = file.tell()  # the reader has consumed exactly this record
            if isinstance(record, Chunk):
                try:
                    yield [r for r in breakup_chunk(record, validate_crc=True)
                           if isinstance(r, (Schema, Channel, Message))]
                except READ_ERRORS:
                    scan.damaged_chunks += 1
            elif isinstance(record, (Schema, Channel, Message)):
                yield [record]
    except READ_ERRORS:
        return  # a truncated tail: the data ends at the last whole record


def _copy(chunks: Iterator[list[Decoded]], writer: BagFileWriter) -> tuple[int, int, int]:
    """Write the chunks' records through ``writer``; return (chunks, messages, orphans)."""
    schema_ids: dict[int, int] = {}
    channel_ids: dict[int, int] = {}
    count = messages = orphans = 0
    for records in chunks:
        for record in records:
            if isinstance(record, Schema):
                schema_ids[record.id] = writer.add_schema(
                    record.name, record.encoding, record.data.decode())
            elif isinstance(record, Channel):
                if record.schema_id in schema_ids:  # else its type is lost: orphans follow
                    channel_ids[record.id] = writer.add_channel(
                        record.topic, schema_ids[record.schema_id], record.metadata,
                        record.message_encoding)
            elif record.channel_id in channel_ids:
                writer.write(channel_ids[record.channel_id], record.log_time, record.data,
                             record.sequence, record.publish_time)
                messages += 1
            else:
                orphans += 1
        writer.flush()  # one chunk out per chunk in
        count += 1
    return count, messages, orphans


def rebuild(source: Path, target: Path) -> Recovery:
    """Write the intact chunks of ``source`` into a new, finished MCAP file ``target``."""
    scan = _Scan()
    writer = BagFileWriter(target)
    try:
        with Path(source).open('rb') as file:
            size = os.fstat(file.fileno()).st_size
            if size == 0:  # killed before its header was written: nothing to recover
                chunks = messages = orphans = 0
                scan.end = 0
            else:
                if file.read(len(MAGIC)) != MAGIC:
                    raise IncompleteFile(f'{source}: not an MCAP file (no magic)')
                file.seek(0)
                chunks, messages, orphans = _copy(_intact_chunks(file, size, scan), writer)
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
        except IncompleteFile as error:
            tmp.unlink(missing_ok=True)
            raise IncompleteFile(f'{path}: cannot be recovered: {error}') from error
        os.replace(tmp, path)
    write_metadata(bag_dir)
    return recoveries
