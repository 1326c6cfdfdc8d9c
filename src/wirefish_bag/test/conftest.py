# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the bringup package tests: small bags written as the recorder writes them."""

from dataclasses import dataclass, field
from pathlib import Path

import pytest
from rosbags.typesys import get_typestore, Stores

from wirefish_bag.bag_storage import add_topic, next_file_path, write_metadata
from wirefish_bag.bag_writer import BagFileWriter

TYPE = 'std_msgs/msg/String'
QOS = """- history: keep_last
  depth: 10
  reliability: reliable
  durability: volatile
  deadline: {sec: 9223372036, nsec: 854775807}
  lifespan: {sec: 9223372036, nsec: 854775807}
  liveliness: automatic
  liveliness_lease_duration: {sec: 9223372036, nsec: 854775807}
  avoid_ros_namespace_conventions: false
"""


@dataclass
class WrittenFile:
    """A bag file written in flushes, and where each flush ended in the file."""

    bag_dir: Path
    path: Path
    texts: list[str]  # the messages' payloads, in writing order
    flush_ends: list[int] = field(default_factory=list)  # file size after each flush
    flushed_counts: list[int] = field(default_factory=list)  # messages written by then


def write_file(typestore, bag_dir: Path, flushes: int, per_flush: int,
               topics: tuple[str, ...] = ('/a', '/b'), first: int = 0,
               close: bool = True, recording: dict[str, str] | None = None) -> WrittenFile:
    """
    Write ``flushes`` chunks of ``per_flush`` messages cycling over ``topics``.

    Message ``i`` is received at 1 s + i ms, published 500 ns before, with sequence number i;
    ``recording`` is the recorder's account the file closes with.
    """
    bag_dir.mkdir(exist_ok=True)
    writer = BagFileWriter(next_file_path(bag_dir))
    channels = [add_topic(writer, typestore, topic, TYPE, QOS) for topic in topics]
    msg_class = typestore.types[TYPE]
    written = WrittenFile(bag_dir, writer.path, [])
    for i in range(first, first + flushes * per_flush):
        text = f'message {i}'
        received_ns = 1_000_000_000 + i * 1_000_000
        writer.write(channels[i % len(channels)], received_ns,
                     typestore.serialize_cdr(msg_class(data=text), TYPE), i, received_ns - 500)
        written.texts.append(text)
        if (i - first + 1) % per_flush == 0:
            writer.flush()
            written.flush_ends.append(writer.path.stat().st_size)
            written.flushed_counts.append(len(written.texts))
    if close:
        writer.close(recording)
        write_metadata(bag_dir)
    return written


@pytest.fixture
def typestore():
    """Return the ROS 2 Jazzy store of message types (std_msgs and friends)."""
    return get_typestore(Stores.ROS2_JAZZY)


@pytest.fixture
def finished_bag(tmp_path, typestore) -> WrittenFile:
    """Return a cleanly closed bag: 12 chunks of 10 messages on two topics."""
    return write_file(typestore, tmp_path / 'bag', flushes=12, per_flush=10)


@pytest.fixture
def killed_bag(tmp_path, typestore) -> WrittenFile:
    """Return a bag whose writer stopped after 12 flushes: no summary, no metadata.yaml."""
    return write_file(typestore, tmp_path / 'bag', flushes=12, per_flush=10, close=False)


@pytest.fixture
def write_bag(typestore):
    """Return ``write(bag_dir, flushes, per_flush, first=0, close=True) -> WrittenFile``."""
    return lambda *args, **kwargs: write_file(typestore, *args, **kwargs)


@pytest.fixture
def offered_qos() -> str:
    """Return the offered QoS (YAML) the sample bags record for every topic."""
    return QOS
