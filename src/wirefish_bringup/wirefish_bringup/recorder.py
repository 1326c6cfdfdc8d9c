"""
Record the graph's topics into a rosbag2 bag (MCAP storage), like `ros2 bag record`.

Subscriptions are raw (serialised CDR bytes go into the bag untouched, no decode/encode cost),
with a QoS matched to each topic's publishers, and topics that appear later are picked up by a
periodic rescan, so the recorder can start before or after the nodes.
"""

from pathlib import Path

from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rosbags.rosbag2 import StoragePlugin, Writer

from wirefish_bringup.bagfile import wirefish_typestore
from wirefish_bringup.sequence_gaps import SequenceGaps
from wirefish_bringup.topics import graph_topics, matching_qos, message_class

BAG_VERSION = 9  # rosbag2 metadata version of ROS 2 Jazzy
QUEUE_DEPTH = 1000


class BagRecorder(Node):
    """Subscribes to every topic under a namespace (and /diagnostics) and writes a bag."""

    def __init__(self, bag_path: Path, namespace: str, rescan_period_s: float = 0.5) -> None:
        super().__init__('wirefish_recorder')
        self.bag_path = bag_path
        self._namespace = namespace
        self._typestore = wirefish_typestore()
        self._writer = Writer(bag_path, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
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
            self._connections[topic] = self._writer.add_connection(
                topic, type_name, typestore=self._typestore)
            self.counts[topic] = 0
            self.lost[topic] = 0
            self.sequences[topic] = SequenceGaps()
            self.create_subscription(
                msg_class, topic, self._make_callback(topic),
                matching_qos(self, topic, QUEUE_DEPTH), raw=True,
                event_callbacks=SubscriptionEventCallbacks(
                    message_lost=lambda info, topic=topic: self._on_lost(topic, info)))
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
            self._writer.write(connection, now, data)
            self.counts[topic] += 1
            sequence.add(info.get('publication_sequence_number'))
        return on_message

    def _on_lost(self, topic: str, info) -> None:
        self.lost[topic] += info.total_count_change
        self.get_logger().warning(f'{topic}: {info.total_count_change} messages lost in transport')

    def close(self) -> None:
        """Finish the bag (MCAP summary and metadata.yaml); idempotent."""
        if not self._closed:
            self._closed = True
            self._writer.close()
