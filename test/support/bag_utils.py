# SPDX-License-Identifier: Apache-2.0
"""Checks of recorded bags for the cross-process tests (recorder kill, graph kill, e2e)."""

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
import subprocess
import sys

from mcap.reader import make_reader
from mcap.records import Channel, DataEnd, Message
from mcap.stream_reader import StreamReader
from wirefish_bag.bag_storage import READ_ERRORS, storage_files
from wirefish_bag.bagfile import read_bag
import yaml


def reindex_bag(bag_path: Path, env: dict[str, str] | None = None) -> str:
    """Run the documented repair step, `wirefish bag reindex BAG`; return what it printed."""
    result = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'bag', 'reindex', str(bag_path)],
        env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


def assert_bag_readable(bag_path: Path) -> dict[str, int]:
    """
    Assert that rosbags and mcap's reader open the bag; return messages per topic.

    rosbags decodes every message; mcap's indexed reader (summary, chunk indexes) must find the
    same messages; metadata.yaml must count exactly what the files hold (what `ros2 bag info`
    would show).
    """
    bag = read_bag(Path(bag_path))  # decodes every message: a damaged one raises here
    counts = {topic: len(messages) for topic, messages in bag.messages.items()}
    indexed: dict[str, int] = {topic: 0 for topic in counts}
    for path in storage_files(Path(bag_path)):
        with path.open('rb') as file:
            for _, channel, _ in make_reader(file).iter_messages():
                indexed[channel.topic] = indexed.get(channel.topic, 0) + 1
    assert indexed == counts, f"mcap's reader finds {indexed}, rosbags {counts}"
    info = yaml.safe_load((Path(bag_path) / 'metadata.yaml').read_text())
    listed = {entry['topic_metadata']['name']: entry['message_count']
              for entry in info['rosbag2_bagfile_information']['topics_with_message_count']}
    assert counts == listed, f'metadata.yaml {listed} but the files hold {counts}'
    return counts


def counters(bag_path: Path, topic: str) -> list[int]:
    """Return the counter that ros_peers' body_wave_talker puts in y[2], per recorded message."""
    return [int(msg.y[2]) for _, msg in read_bag(Path(bag_path), [topic]).messages[topic]]


@dataclass(frozen=True)
class SequenceGap:
    """Publisher sequence numbers absent from a bag: ``missing`` between two recorded times."""

    topic: str
    missing: int
    after_s: float  # receive time of the last message before the gap (system clock)
    before_s: float  # receive time of the first message after it

    @property
    def first_missing_s(self) -> float:
        """Return about when the first missing message came (at the gap's mean spacing)."""
        return self.after_s + (self.before_s - self.after_s) / (self.missing + 1)


def _messages(path: Path, *, being_written: bool = False) -> Iterator[tuple[str, Message]]:
    """
    Yield (topic, message) for each message of an MCAP file, in file order (mcap's reader).

    ``being_written``: the file's writer is still at work; its torn tail ends the messages.
    """
    topics: dict[int, str] = {}
    with Path(path).open('rb') as file:
        try:
            for record in StreamReader(file, validate_crcs=True).records:
                if isinstance(record, DataEnd):  # the summary and footer follow
                    return
                if isinstance(record, Channel):
                    topics[record.id] = record.topic
                elif isinstance(record, Message):
                    yield topics[record.channel_id], record
        except READ_ERRORS:
            if not being_written:
                raise


def sequence_gaps(bag_path: Path) -> tuple[list[SequenceGap], dict[str, int]]:
    """
    Return the gaps in every topic's publisher sequence numbers, and each topic's writer runs.

    The recorder stores each message's DDS publication sequence number in the MCAP message.
    Within one writer the numbers rise by one; a number at or below the last one starts a new
    run (a restarted publisher, or a latched sample sent again to a restarted recorder), whose
    first number is not a gap. Files are read in recording order.
    """
    runs: dict[str, int] = {}
    last: dict[str, tuple[int, int]] = {}
    gaps: list[SequenceGap] = []
    for path in storage_files(Path(bag_path)):
        for topic, message in _messages(path):
            previous = last.get(topic)
            if previous is None or message.sequence <= previous[0]:
                runs[topic] = runs.get(topic, 0) + 1
            elif message.sequence > previous[0] + 1:
                gaps.append(SequenceGap(topic, message.sequence - previous[0] - 1,
                                        previous[1] * 1e-9, message.log_time * 1e-9))
            last[topic] = (message.sequence, message.log_time)
    return gaps, runs


def flushed_topics(path: Path) -> set[str]:
    """Return the topics with a message in the flushed chunks of an MCAP file being written."""
    return {topic for topic, _ in _messages(path, being_written=True)}


def publish_lags(bag_path: Path) -> dict[str, tuple[list[float], list[float]]]:
    """Return {topic: (receive times s, publish times s)} of every message in the bag's files."""
    times: dict[str, tuple[list[float], list[float]]] = {}
    for path in storage_files(Path(bag_path)):
        for topic, message in _messages(path):
            received, published = times.setdefault(topic, ([], []))
            received.append(message.log_time * 1e-9)
            published.append(message.publish_time * 1e-9)
    return times
