"""
A rosbag2 bag directory: its MCAP files and the metadata.yaml that rosbag2 Jazzy writes.

A bag is ``<dir>/metadata.yaml`` plus ``<dir>/<dir>_0.mcap``, ``<dir>_1.mcap``, ... (the names
of rosbag2's split files; a recorder resumed after a kill adds the next one). metadata.yaml is
always built from the files' own MCAP summaries, so it can never disagree with them.
"""

from dataclasses import dataclass
import os
from pathlib import Path
import re

from rosbags.typesys.store import Typestore

from wirefish_bringup import mcap_records as rec
from wirefish_bringup.mcap_writer import McapWriter
import yaml

METADATA_FILE = 'metadata.yaml'
BAG_VERSION = 9  # rosbag2 metadata version of ROS 2 Jazzy
QOS_KEY = 'offered_qos_profiles'  # the channel metadata keys rosbag2's MCAP plugin writes
HASH_KEY = 'topic_type_hash'


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


def add_topic(writer: McapWriter, typestore: Typestore, topic: str, type_name: str,
              offered_qos_profiles: str) -> int:
    """Add ``topic`` to ``writer`` with its type's definition from ``typestore``; return its id."""
    definition, _ = typestore.generate_msgdef(type_name, ros_version=2)
    schema_id = writer.add_schema(type_name, 'ros2msg', definition)
    return writer.add_channel(topic, schema_id, {
        QOS_KEY: offered_qos_profiles, HASH_KEY: typestore.hash_rihs01(type_name)})


def _summary_section(path: Path) -> tuple[bytes, int, int]:
    """Return the summary section's bytes and where it and its offsets start (footer first)."""
    with path.open('rb') as file:
        size = file.seek(0, os.SEEK_END)
        file.seek(0)
        if size < 2 * len(rec.MAGIC) + rec.FOOTER_SIZE or file.read(8) != rec.MAGIC:
            raise rec.RecordError('too short, or not an MCAP file')
        file.seek(size - rec.FOOTER_SIZE)
        summary_start, offsets_start = rec.decode_footer(file.read(rec.FOOTER_SIZE))
        if not 0 < summary_start <= offsets_start <= size - rec.FOOTER_SIZE:
            raise rec.RecordError('the footer points to no summary')
        file.seek(summary_start)
        return file.read(size - rec.FOOTER_SIZE - summary_start), summary_start, offsets_start


def read_file_info(path: Path) -> FileInfo:
    """Return what the summary of the MCAP file ``path`` says; IncompleteFile if it has none."""
    try:
        summary, summary_start, offsets_start = _summary_section(Path(path))
        schemas, channels, counts, start_ns, end_ns = {}, [], None, 0, 0
        for opcode, _, content in rec.iter_records(summary, 0, offsets_start - summary_start):
            if opcode == rec.SCHEMA:
                schema = rec.decode_schema(content)
                schemas[schema.schema_id] = schema.name
            elif opcode == rec.CHANNEL:
                channels.append(rec.decode_channel(content))
            elif opcode == rec.STATISTICS:
                counts, start_ns, end_ns = rec.decode_statistics(content)
    except rec.RecordError as error:
        raise IncompleteFile(f'{path}: {error}') from error
    if counts is None:
        raise IncompleteFile(f'{path}: the summary has no statistics')
    topics = tuple(TopicInfo(c.topic, schemas.get(c.schema_id, ''), c.metadata.get(QOS_KEY, ''),
                             c.metadata.get(HASH_KEY, ''), counts.get(c.channel_id, 0))
                   for c in channels)
    total = sum(counts.values())
    return FileInfo(Path(path).name, start_ns if total else 0, end_ns if total else 0, total,
                    topics)


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
        'custom_data': None,
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
