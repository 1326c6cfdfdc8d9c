# SPDX-License-Identifier: Apache-2.0
"""
A node that holds the virtual fish's clock at its timer's ticks (the simulated-time road).

fish_sim owns the graph's clock under `wirefish up --sim` and steps it in lockstep
(``wirefish_sim.lockstep``). A node whose timer must see every period of simulated time says,
after each tick, when its next one is due: fish_sim takes no step past that time until the
node's next answer. The answer is a std_msgs/Header on ``lockstep/next_tick``: the due time as
its stamp, the node's fully qualified name as its frame_id (fish_sim keeps one hold per name,
so a restarted node takes its predecessor's place). Off simulated time a node says nothing.
"""

from __future__ import annotations

from typing import Any

from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.timer import Timer
from std_msgs.msg import Header
from wirefish_common.qos import HOLD
from wirefish_common.topics import LOCKSTEP_HOLD_TOPIC


# A due time the clock never reaches (the last second a Time's int32 seconds can say): a hold
# at it holds nothing, so a node that is done says it rather than wait to be released.
RELEASED_NS = (2 ** 31 - 1) * 1_000_000_000
RELEASE_ACK_S = 1.0  # how long a release waits for fish_sim to have it (wall s)


class ClockHold:
    """Says a node's next tick to the clock's owner when the node runs on simulated time."""

    def __init__(self, node: Node, simulated: bool | None = None) -> None:
        """
        Publish on ``node``'s ``lockstep/next_tick`` if it runs on simulated time.

        ``simulated`` None: if the node runs with use_sim_time; a node that reads the graph's
        clock itself (`wirefish mission` hears ``<namespace>/clock``) says so.
        """
        self._node = node
        if simulated is None:
            simulated = bool(node.get_parameter('use_sim_time').value)
        self._publisher: Any = (node.create_publisher(Header, LOCKSTEP_HOLD_TOPIC, HOLD)
                                if simulated else None)

    @property
    def on_simulated_time(self) -> bool:
        """Return whether the node holds the clock (it runs on simulated time)."""
        return self._publisher is not None

    def say_next_tick(self, timer: Timer) -> None:
        """Publish when ``timer``'s next tick is due (call it once the tick's work is done)."""
        until_ns = timer.time_until_next_call()
        if self._publisher is None or until_ns is None:
            return
        self.say_due(self._node.get_clock().now().nanoseconds + max(0, until_ns))

    def say_due(self, due_ns: int) -> None:
        """
        Publish that the node's next tick is due at ``due_ns`` of simulated time.

        For a node that paces itself without a timer; ``due_ns`` must be a time the clock
        takes (a whole number of fish_sim's steps from a time it said), or the clock stops
        short of it and waits for the node until it is released.
        """
        if self._publisher is None:
            return
        sec, nanosec = divmod(due_ns, 1_000_000_000)
        header = Header(frame_id=self._node.get_fully_qualified_name())
        header.stamp.sec, header.stamp.nanosec = sec, nanosec
        self._publisher.publish(header)

    def release(self) -> None:
        """Say that no tick of the node is due any more: the clock runs on without it."""
        self.say_due(RELEASED_NS)
        if self._publisher is not None:   # before the node goes: else it holds until released
            self._publisher.wait_for_all_acked(Duration(seconds=RELEASE_ACK_S))
