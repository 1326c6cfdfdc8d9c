# SPDX-License-Identifier: Apache-2.0
"""
A subscription the executor never wakes for: its messages wait in the reader's queue.

A Python node pays ~0.18 ms of CPU per message its executor hands to a callback (most of it the
wake-up, not the callback: docs/PROFILING.md). A consumer that works on its own timer and needs
every sample, but not at once, takes them in batches instead: ``BatchIntake`` subscribes from a
second node of the same context that no executor spins (named ``<node>_intake``, without rosout
or parameter services, so only the subscription is on the graph), on the main node's resolved
topic name (its namespace and remappings), and ``take()`` returns the serialized messages that
arrived since the last call, oldest first. The queue holds ``depth`` messages (keep last): a
consumer must take them at least every ``depth`` messages.
"""

from __future__ import annotations

import math
from typing import Any

MAX_INTAKE_DEPTH = 4096
MIN_INTAKE_DEPTH = 16


def intake_qos(fastest_source_hz: float, tick_rate_hz: float) -> Any:
    """
    Return a batch intake's QoS: sensor data, its queue two ticks deep at the fastest source.

    Keep-last drops the oldest sample when the queue is full: two ticks' worth at the fastest
    rate the source may publish means a tick that comes late loses none.
    """
    from rclpy.qos import QoSProfile
    from wirefish_common.qos import SENSOR_DATA

    depth = min(MAX_INTAKE_DEPTH,
                max(MIN_INTAKE_DEPTH, math.ceil(2.0 * fastest_source_hz / tick_rate_hz)))
    return QoSProfile(depth=depth, reliability=SENSOR_DATA.reliability,
                      durability=SENSOR_DATA.durability, history=SENSOR_DATA.history)


def _never_called(_msg: Any) -> None:  # no executor spins the reader node
    raise AssertionError('a BatchIntake subscription is never spun')


class BatchIntake:
    """Serialized messages of ``topic`` (resolved as ``node`` resolves it), taken on demand."""

    def __init__(self, node: Any, msg_type: Any, topic: str, qos: Any) -> None:
        """Subscribe from a reader node of ``node``'s context that no executor spins."""
        from rclpy.node import Node

        self._msg_type = msg_type
        self.topic = node.resolve_topic_name(topic)
        self._reader = Node(f'{node.get_name()}_intake', namespace=node.get_namespace(),
                            context=node.context, use_global_arguments=False,
                            enable_rosout=False, start_parameter_services=False)
        self._subscription = self._reader.create_subscription(
            msg_type, self.topic, _never_called, qos, raw=True)

    def take(self) -> list[bytes]:
        """Return the serialized messages that arrived since the last call, oldest first."""
        taken = []
        handle = self._subscription.handle
        while (sample := handle.take_message(self._msg_type, True)) is not None:
            taken.append(sample[0])
        return taken

    def destroy(self) -> None:
        """Unsubscribe and destroy the reader node."""
        self._reader.destroy_subscription(self._subscription)
        self._reader.destroy_node()
