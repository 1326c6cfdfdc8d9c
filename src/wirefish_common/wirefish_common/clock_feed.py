# SPDX-License-Identifier: Apache-2.0
"""
A node's simulated time taken from /clock on a companion node and a thread of its own.

A node on ``use_sim_time`` subscribes /clock itself, so its executor wakes at every tick of the
clock (100 Hz on the virtual fish's lockstep clock). On the events executor a wake costs
microseconds; on rclpy's ``MultiThreadedExecutor`` it costs milliseconds of Python (the wait set
is rebuilt, and the loop spins until a pool thread has taken the message). The tuner needs that
executor (its service blocks for a fit while other requests are answered at once), and idle on
the lockstep clock it took 69 % of a core, more than the rest of the graph together (6.9 s of
CPU in 10 s; 0.06 s with ``use_sim_time`` false; 0.8 s on the classic executor).

``ClockFeed.start(node)`` moves that subscription to ``<node name>_clock``, a node of the same
process and namespace (as the bridge's calibration services live on ``bridge_node_calibration``)
spun by the events executor on a thread of its own; each tick sets the node's ROS time, which is
what rclpy's own subscription did (``rclpy.time_source.TimeSource.clock_callback``). The node
keeps its ``use_sim_time`` parameter and the switch it makes: false puts its clock on the wall
clock, true back on the ticks the feed keeps setting. A node started on the wall clock gets no
feed (nothing to move).
"""

from __future__ import annotations

import threading

from rclpy.clock import ROSClock
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.time import Time
from rosgraph_msgs.msg import Clock
from wirefish_common.executors import make_executor, settle, spin_until_stopped, wake

# What rclpy's own /clock subscription asks for: the newest tick only, best effort.
CLOCK_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)


class ClockFeed:
    """Sets ``node``'s ROS time from /clock on a companion node spun on its own thread."""

    def __init__(self, node: Node, topic: str) -> None:
        """Subscribe ``topic`` (the node's resolved /clock) on the companion node; spin it."""
        clock = node.get_clock()
        if not isinstance(clock, ROSClock):
            raise TypeError(f'{node.get_name()} keeps no ROS clock to feed')
        self._clock = clock
        # No global arguments: the process's node-name remap would name it like the node.
        self.node = Node(f'{node.get_name()}_clock', namespace=node.get_namespace(),
                         context=node.context, use_global_arguments=False,
                         start_parameter_services=False)
        self.node.create_subscription(Clock, topic, self._on_clock, CLOCK_QOS)
        self._executor = make_executor('events', context=node.context)
        self._executor.add_node(self.node)
        self._stopped = False
        self._thread = threading.Thread(target=self._spin, name=f'{self.node.get_name()}',
                                        daemon=True)
        self._thread.start()

    @classmethod
    def start(cls, node: Node) -> ClockFeed | None:
        """Move ``node``'s /clock subscription to a feed; None if it is on the wall clock."""
        ticks = [sub for sub in node.subscriptions if sub.msg_type is Clock]
        if not ticks:
            return None
        topic = ticks[0].topic_name  # resolved: the process's /clock remap applied
        # rclpy has no public handle on a node's time source; detaching it drops its /clock
        # subscription and leaves its use_sim_time switch in place.
        node._time_source.detach_node()
        return cls(node, topic)

    def _on_clock(self, message: Clock) -> None:
        self._clock.set_ros_time_override(Time.from_msg(message.clock))

    def _spin(self) -> None:
        try:
            spin_until_stopped(self._executor, lambda: self._stopped)
        except (ExternalShutdownException, RuntimeError):
            pass  # the context went down under the loop: the process is stopping

    def close(self) -> None:
        """Stop the thread, then take the companion node out of the graph."""
        self._stopped = True
        try:
            wake(self._executor)
        except RuntimeError:  # the context is already shut down
            pass
        self._thread.join(timeout=2.0)
        self._executor.remove_node(self.node)
        try:
            settle(self._executor)
        except (ExternalShutdownException, RuntimeError):
            pass
        self.node.destroy_node()
