# SPDX-License-Identifier: Apache-2.0
"""
A test as the owner of a node's simulated clock, as fish_sim is on `wirefish up --sim`.

``ClockOwner`` publishes ``<namespace>/clock`` and reads what the node under test answers on
``lockstep/next_tick`` (the time its next tick is due, and its name); one executor spins both.
"""

from __future__ import annotations

from typing import Any


def stamp(time_ns: int) -> Any:
    """Return ``time_ns`` as a builtin_interfaces/Time."""
    from builtin_interfaces.msg import Time
    return Time(sec=time_ns // 10**9, nanosec=time_ns % 10**9)


def on_simulated_time(namespace: str) -> dict[str, Any]:
    """Return the keyword arguments that put an in-process node on ``namespace``'s clock."""
    from rclpy.parameter import Parameter
    return {'namespace': namespace,
            'cli_args': ['--ros-args', '-r', f'/clock:={namespace}/clock'],
            'parameter_overrides': [Parameter('use_sim_time', value=True)]}


class ClockOwner:
    """The clock of ``held`` (a node on ``on_simulated_time(namespace)``), set by the test."""

    def __init__(self, context: Any, namespace: str, held: Any) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import Header
        from wirefish_common.qos import CLOCK, HOLD
        from wirefish_common.topics import LOCKSTEP_HOLD_TOPIC

        self.node = rclpy.create_node('clock_owner', namespace=namespace, context=context)
        self.answers: list[int] = []  # the next ticks the held node said, in order (ns)
        self.holders: set[str] = set()  # the names it said them under
        self.node.create_subscription(Header, LOCKSTEP_HOLD_TOPIC, self._on_answer, HOLD)
        self._clock = self.node.create_publisher(Clock, 'clock', CLOCK)
        self._clock_type = Clock
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(held)
        self.executor.add_node(self.node)

    def _on_answer(self, msg: Any) -> None:
        self.answers.append(msg.stamp.sec * 10**9 + msg.stamp.nanosec)
        self.holders.add(msg.frame_id)

    def set_clock(self, time_ns: int) -> None:
        """Publish ``time_ns`` as the clock."""
        self._clock.publish(self._clock_type(clock=stamp(time_ns)))

    def close(self) -> None:
        """Stop the executor and destroy the owner's node (not the held one)."""
        self.executor.shutdown()
        self.node.destroy_node()
