# SPDX-License-Identifier: Apache-2.0
"""
link_relay: the fish's side of the radio link, the decimated copies the shore sees.

Runs on the fish (``wirefish up --role fish``). For each row of the crossing table
(``crossing_file``, default config/crossing.yaml; see ``wirefish_relay.crossing``) it
subscribes to the fish's topic and republishes it under ``shore/``: the newest message on each
tick of the row's ``rate_hz``, or every message (rate 0). Messages are relayed serialized, never
deserialized: the relay costs a copy of bytes, not a Python message per sample.
"""

from __future__ import annotations

from rclpy.node import Node
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import LATCHED, RELIABLE, SENSOR_DATA
from wirefish_common.topics import message_class
from wirefish_relay.crossing import CrossingTopic, LatestHold, load_crossing
from wirefish_relay.link_relay_parameters import TABLE

QOS = {'sensor': SENSOR_DATA, 'reliable': RELIABLE, 'latched': LATCHED}


class LinkRelay(Node):
    """Fish topics in, their ``shore/`` copies out at the crossing table's rates."""

    def __init__(self, **kwargs) -> None:
        """Read the crossing table (read-only parameter) and wire one relay per row."""
        super().__init__('link_relay', **kwargs)
        # A file that does not load is refused at start-up (InvalidParameters, with the reason).
        self._node_parameters = NodeParameters(self, TABLE)
        self.table = load_crossing(self._node_parameters.str_value('crossing_file'))
        for row in self.table:
            self._relay(row)
        self.get_logger().info('relaying to shore/: ' + ', '.join(
            f'{r.topic} {"every message" if r.rate_hz == 0 else f"{r.rate_hz:g} Hz"}'
            for r in self.table))

    def _relay(self, row: CrossingTopic) -> None:
        kind = message_class(row.type_name)
        publisher = self.create_publisher(kind, row.shore_topic, QOS[row.qos])
        if row.rate_hz == 0.0:
            self.create_subscription(kind, row.topic, publisher.publish, QOS[row.qos], raw=True)
            return
        hold = LatestHold()
        self.create_subscription(kind, row.topic, hold.put, QOS[row.qos], raw=True)

        def send() -> None:
            message = hold.take()
            if message is not None:
                publisher.publish(message)
        self.create_timer(1.0 / row.rate_hz, send)


def main(args: list[str] | None = None) -> None:
    """Run the relay until shutdown."""
    run_node(LinkRelay, args)
