# SPDX-License-Identifier: Apache-2.0
"""
A rosbag2 bag directory: its MCAP files and the metadata.yaml that rosbag2 Jazzy writes.

A bag is ``<dir>/metadata.yaml`` plus ``<dir>/<dir>_0.mcap``, ``<dir>_1.mcap``, ... (the names
of rosbag2's split files; a recorder resumed after a kill adds the next one). metadata.yaml is
always built from the files' own MCAP summaries (read with the ``mcap`` library's reader), so
it can never disagree with them. What the recorder counted (messages missing from the
publishers' sequences, how late they were taken) is each file's ``wirefish_recording`` metadata
record, summed over the files into metadata.yaml's ``custom_data``.
"""

from dataclasses import dataclass, field
import os
from pathlib import Path
import re
import struct

from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from rosbags.typesys.store import Typestore

from wirefish_bag.bag_writer import BagFileWriter, RECORDING_METADATA
from wirefish_bag.sequence_gaps import merged_recording
import yaml

METADATA_FILE = 'metadata.yaml'
BAG_VERSION = 9  # rosbag2 metadata version of ROS 2 Jazzy
QOS_KEY = 'offered_qos_profiles'  # the channel metadata keys rosbag2's MCAP plugin writes
HASH_KEY = 'topic_type_hash'
MAGIC = b'\x89MCAP0\r\n'
# Errors of mcap's reader on bytes that are no (whole) MCAP file: a file's tail cut by a kill.
READ_ERRORS = (McapError, struct.error, ValueError, EOFError, KeyError)


class IncompleteFile(ValueError):
    """An MCAP file without a valid summary and footer (its writer was killed)."""


@dataclass(frozen=True)
class TopicInfo:
    """One topic of one file: what metadata.yaml says about it."""

    name: str
    type_name: str
    offered_qos_profiles: str  # YAML, as in the channel metadata
    type_hash: str
    message_count: int


@dataclass(frozen=True)
class FileInfo:
    """One finished MCAP file, from its summary section."""

    name: str
    start_ns: int
    end_ns: int
    message_count: int
    topics: tuple[TopicInfo, ...]
    recording: dict[str, str] = field(default_factory=dict)  # the recorder's own account


def _split_index(path: Path) -> int:
    match = re.search(r'_(\d+)\.mcap$', path.name)
    return int(match.group(1)) if match else -1  # a file named otherwise comes first


def storage_files(bag_dir: Path) -> list[Path]:
    """Return the bag's MCAP files in recording order (by their split index)."""
    return sorted(Path(bag_dir).glob('*.mcap'), key=lambda p: (_split_index(p), p.name))


def next_file_path(bag_dir: Path) -> Path:
    """Return the path of the bag's next split file (``<dir>_<n>.mcap``)."""
    bag_dir = Path(bag_dir)
    index = max((_split_index(p) for p in storage_files(bag_dir)), default=-1) + 1
    return bag_dir / f'{bag_dir.name}_{index}.mcap'


def add_topic(writer: BagFileWriter, typestore: Typestore, topic: str, type_name: str,
              offered_qos_profiles: str) -> int:
    """
    Add ``topic`` to ``writer`` with its type's definition from ``typestore``; return its id.

    The type hash is the typestore's RIHS01 (the one rosidl computes, and the one rosbags checks
    on reading; an action's feedback publisher announces another).
    """
    definition, _ = typestore.generate_msgdef(type_name, ros_version=2)
    schema_id = writer.add_schema(type_name, 'ros2msg', definition)
    return writer.add_channel(topic, schema_id, {
        QOS_KEY: offered_qos_profiles, HASH_KEY: typestore.hash_rihs01(type_name)})


def read_file_info(path: Path) -> FileInfo:
    """Return what the summary of the MCAP file ``path`` says; IncompleteFile if it has none."""
    path = Path(path)
    with path.open('rb') as file:
        size = file.seek(0, os.SEEK_END)
        file.seek(size - len(MAGIC) if size >= 2 * len(MAGIC) else 0)
        # A killed file ends in the middle of a chunk: no closing magic, no footer to read.
        if size < 2 * len(MAGIC) or file.read(len(MAGIC)) != MAGIC:
            raise IncompleteFile(f'{path}: no footer (too short, or not a finished MCAP file)')
        file.seek(0)
        reader = SeekingReader(file)
        try:
            summary = reader.get_summary()
            recording: dict[str, str] = {}
            for record in reader.iter_metadata() if summary is not None else ():
                if record.name == RECORDING_METADATA:
                    recording.update(record.metadata)
        except READ_ERRORS as error:
            raise IncompleteFile(f'{path}: {error}') from error
    if summary is None or summary.statistics is None:
        raise IncompleteFile(f'{path}: the summary has no statistics')
    stats = summary.statistics
    schemas = {i: s.name for i, s in summary.schemas.items()}
    topics = tuple(TopicInfo(c.topic, schemas.get(c.schema_id, ''), c.metadata.get(QOS_KEY, ''),
                             c.metadata.get(HASH_KEY, ''),
                             stats.channel_message_counts.get(c.id, 0))
                   for c in summary.channels.values())
    total = stats.message_count
    return FileInfo(path.name, stats.message_start_time if total else 0,
                    stats.message_end_time if total else 0, total, topics, recording)


def rosbag2_metadata(files: list[FileInfo]) -> dict:
    """
    Return metadata.yaml's content for a bag of ``files``, as rosbag2 Jazzy (version 9) writes it.

    A topic in several files (a resumed recording) is listed once, with its message counts
    summed and the offered QoS of the file it first appeared in.
    """
    topics: dict[tuple[str, str], dict] = {}
    for info in files:
        for topic in info.topics:
            entry = topics.setdefault((topic.name, topic.type_name), {
                'topic_metadata': {
                    'name': topic.name,
                    'type': topic.type_name,
                    'serialization_format': 'cdr',
                    'offered_qos_profiles': yaml.safe_load(topic.offered_qos_profiles) or [],
                    'type_description_hash': topic.type_hash,
                },
                'message_count': 0,
            })
            entry['message_count'] += topic.message_count
    with_messages = [f for f in files if f.message_count]
    start = min((f.start_ns for f in with_messages), default=0)
    end = max((f.end_ns for f in with_messages), default=0)
    return {'rosbag2_bagfile_information': {
        'version': BAG_VERSION,
        'storage_identifier': 'mcap',
        'duration': {'nanoseconds': end - start},
        'starting_time': {'nanoseconds_since_epoch': start},
        'message_count': sum(f.message_count for f in files),
        'topics_with_message_count': list(topics.values()),
        'compression_format': '',
        'compression_mode': '',
        'relative_file_paths': [f.name for f in files],
        'files': [{
            'path': f.name,
            'starting_time': {'nanoseconds_since_epoch': f.start_ns},
            'duration': {'nanoseconds': f.end_ns - f.start_ns},
            'message_count': f.message_count,
        } for f in files],
        'custom_data': merged_recording([f.recording for f in files]) or None,
        'ros_distro': 'jazzy',
    }}


def write_metadata(bag_dir: Path) -> dict:
    """Write ``bag_dir``/metadata.yaml from its files' summaries (atomically); return it."""
    bag_dir = Path(bag_dir)
    metadata = rosbag2_metadata([read_file_info(p) for p in storage_files(bag_dir)])
    tmp = bag_dir / (METADATA_FILE + '.tmp')
    tmp.write_text(yaml.safe_dump(metadata, sort_keys=False, default_flow_style=False))
    os.replace(tmp, bag_dir / METADATA_FILE)
    return metadata


def recording_custom_data(bag_dir: Path) -> dict | None:
    """Return the custom_data of ``bag_dir``'s metadata.yaml (the recorder's account), if any."""
    try:
        info = yaml.safe_load((Path(bag_dir) / METADATA_FILE).read_text())
        return info['rosbag2_bagfile_information'].get('custom_data')
    except (OSError, yaml.YAMLError, KeyError, TypeError, AttributeError):
        return None
