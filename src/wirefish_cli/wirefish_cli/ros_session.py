# SPDX-License-Identifier: Apache-2.0
"""
What every verb that talks to the graph opens and closes: ROS, one node, one executor.

A verb is a short-lived process: it owns its ROS context, so it starts it without rclpy's
signal handlers (the verb's own Ctrl-C handling stays in charge) and shuts it down on every
way out, error or not, in the reverse order of the opening.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
import time
from typing import TYPE_CHECKING

from wirefish_cli.api import UsageError

if TYPE_CHECKING:  # rclpy is imported when a session opens: `wirefish --help` stays fast
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

# How often a waiting verb takes its callbacks (a Ctrl-C is seen within this too).
SPIN_STEP_S = 0.05


def graph_namespace(namespace: str) -> str:
    """Return ``namespace`` as an absolute ROS namespace, or raise UsageError saying why."""
    from wirefish_bringup.graph import validate_namespace

    try:
        return validate_namespace(namespace)
    except ValueError as error:
        raise UsageError(str(error)) from None


@dataclass
class RosSession:
    """The open session: the verb's node, the executor that spins it and its namespace."""

    node: Node
    executor: SingleThreadedExecutor
    namespace: str

    def spin_once(self, timeout_s: float = SPIN_STEP_S) -> None:
        """Take the callbacks that are ready, waiting at most ``timeout_s`` for one."""
        self.executor.spin_once(timeout_sec=timeout_s)

    def spin_until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """Spin until ``done()`` or ``timeout_s`` has passed; return ``done()``."""
        deadline = time.monotonic() + timeout_s
        while not done() and time.monotonic() < deadline:
            self.spin_once(min(SPIN_STEP_S, max(0.0, deadline - time.monotonic())))
        return done()


@contextmanager
def ros_session(node_name: str, namespace: str = '/', *,
                make_node: Callable[[str], Node] | None = None,
                parameter_services: bool = False,
                rcl_args: list[str] | None = None) -> Iterator[RosSession]:
    """
    Open ROS for a verb and close it on the way out.

    ``namespace`` is validated first (UsageError, before anything is opened). ``make_node``
    builds the verb's own Node subclass from the validated namespace; without it the session's
    node is a plain node named ``node_name``. ``rcl_args`` are rclpy.init's arguments (a verb
    whose own options look like ROS remaps passes only the program name).
    """
    namespace = graph_namespace(namespace)
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(args=rcl_args, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = (make_node(namespace) if make_node is not None else
                rclpy.create_node(node_name, namespace=namespace,
                                  start_parameter_services=parameter_services))
        try:
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            try:
                yield RosSession(node, executor, namespace)
            finally:
                executor.shutdown()
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown()
