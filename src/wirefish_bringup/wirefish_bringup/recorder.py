"""
Record the graph's topics into a rosbag2 bag (MCAP storage), like `ros2 bag record`.

Subscriptions are raw (serialised CDR bytes go into the bag untouched, no decode/encode cost),
with a QoS matched to each topic's publishers, and topics that appear later are picked up by a
periodic rescan, so the recorder can start before or after the nodes.

What arrived is flushed to the file every FLUSH_PERIOD_S, so a SIGKILL loses at most that much:
`wirefish bag reindex` makes the killed bag readable (wirefish_bringup.reindex). A recorder
started with ``resume`` on such a bag reindexes it and goes on recording into its next file.
"""

import functools
from pathlib import Path

from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node

from wirefish_bringup.bag_storage import (add_topic, next_file_path, read_file_info,
                                          storage_files, write_metadata)
from wirefish_bringup.bagfile import wirefish_typestore
from wirefish_bringup.mcap_writer import McapWriter
from wirefish_bringup.reindex import reindex
from wirefish_bringup.sequence_gaps import SequenceGaps
from wirefish_bringup.topics import graph_topics, matching_qos, message_class, offered_qos_yaml

QUEUE_DEPTH = 1000
# Half the ~1 s a kill may cost, so a recorder starved for a moment still keeps that bound.
FLUSH_PERIOD_S = 0.5


def open_bag_file(bag_path: Path, resume: bool) -> tuple[McapWriter, dict[str, str]]:
    """
    Start the bag's next MCAP file; return its writer and the QoS already recorded per topic.

    A new bag gets its directory. ``resume`` on an existing bag first makes its files whole
    (a killed recorder's last file is reindexed), and the topics it holds keep the offered QoS
    they were recorded with, so every file of the bag describes a topic the same way.
    """
    known_qos: dict[str, str] = {}
    if resume and bag_path.is_dir() and storage_files(bag_path):
        reindex(bag_path)
        for path in storage_files(bag_path):
            for topic in read_file_info(path).topics:
                known_qos.setdefault(topic.name, topic.offered_qos_profiles)
    else:
        bag_path.mkdir(parents=True, exist_ok=resume)
    return McapWriter(next_file_path(bag_path)), known_qos


class BagRecorder(Node):
    """Subscribes to every topic under a namespace (and /diagnostics) and writes a bag."""

    def __init__(self, bag_path: Path, namespace: str, rescan_period_s: float = 0.5,
                 resume: bool = False) -> None:
        super().__init__('wirefish_recorder')
        self.bag_path = bag_path
        self._namespace = namespace
        self._typestore = wirefish_typestore()
        self._writer, self._known_qos = open_bag_file(bag_path, resume)
        self._connections: dict = {}
        self.counts: dict[str, int] = {}
        # Samples the middleware reports lost on the way to us (DDS 'sample lost' status).
        self.lost: dict[str, int] = {}
        # Samples missing from each publisher's sequence numbers: every cause of loss counted.
        self.sequences: dict[str, SequenceGaps] = {}
        self._closed = False
        self.first_message_ns: int | None = None
        self._scan()
        self.create_timer(rescan_period_s, self._scan)
        self.create_timer(FLUSH_PERIOD_S, self._flush)

    def _scan(self) -> None:
        for topic, type_name in graph_topics(self, self._namespace).items():
            if topic in self._connections:
                continue
            try:
                msg_class = message_class(type_name)
            except (ImportError, AttributeError, ValueError):
                self.get_logger().warning(f'cannot record {topic}: unknown type {type_name}')
                self._connections[topic] = None
                continue
            qos = self._known_qos.get(topic) or offered_qos_yaml(self, topic)
            self._connections[topic] = add_topic(self._writer, self._typestore, topic,
                                                 type_name, qos)
            self.counts[topic] = 0
            self.lost[topic] = 0
            self.sequences[topic] = SequenceGaps()
            self.create_subscription(
                msg_class, topic, self._make_callback(topic),
                matching_qos(self, topic, QUEUE_DEPTH), raw=True,
                event_callbacks=SubscriptionEventCallbacks(
                    message_lost=functools.partial(self._on_lost, topic)))
            self.get_logger().info(f'recording {topic} [{type_name}]')

    def _make_callback(self, topic: str):
        connection = self._connections[topic]
        sequence = self.sequences[topic]

        def on_message(data: bytes, info: dict) -> None:
            if self._closed:
                return
            now = self.get_clock().now().nanoseconds
            if self.first_message_ns is None:
                self.first_message_ns = now
            number = info.get('publication_sequence_number')
            # The publisher's DDS sequence number is the MCAP message's: a bag shows its gaps.
            self._writer.write(connection, now, data, number or 0)
            self.counts[topic] += 1
            sequence.add(number)
        return on_message

    def _on_lost(self, topic: str, info) -> None:
        self.lost[topic] += info.total_count_change
        self.get_logger().warning(f'{topic}: {info.total_count_change} messages lost in transport')

    def _flush(self) -> None:
        if not self._closed:
            self._writer.flush()

    def close(self) -> None:
        """Finish the bag (MCAP summary and metadata.yaml); idempotent."""
        if not self._closed:
            self._closed = True
            self._writer.close()
            write_metadata(self.bag_path)
