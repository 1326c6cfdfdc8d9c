"""
The one ``main()`` of every wirefish node: signals, rclpy, the node, its executor, a clean stop.

``run_node(CpgNode, args)`` is the whole of a node module's ``main()``:

1. SIGINT/SIGTERM are routed through ``SignalShutdown`` before ``rclpy.init`` (rclpy's own
   handlers are off), so a signal stops the node between two callbacks, however many arrive;
2. the node is built; start-up values it refuses (``InvalidParameters``, including a value of
   the wrong type) end the process with one FATAL line and exit code 1, no traceback;
3. the executor (``executor_factory()``, single-threaded by default) spins until a signal;
4. the executor, the node and the context are torn down in that order; exit code 0.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from wirefish_common.parameter_table import InvalidParameters
from wirefish_common.shutdown import SignalShutdown

NodeT = TypeVar('NodeT', bound=Node)


def create_node_or_exit(node_class: Callable[[], NodeT]) -> NodeT:
    """
    Return ``node_class()``; if its start-up parameters are refused, log one FATAL line, exit 1.

    For after ``rclpy.init``: a bad parameter file or ``-p`` then reads as one clear line
    naming the node and the reason, not a traceback.
    """
    try:
        return node_class()
    except InvalidParameters as error:
        rclpy.logging.get_logger('wirefish').fatal(str(error))
        rclpy.try_shutdown()
        raise SystemExit(1) from None


def run_node(node_class: Callable[[], Node], args: list[str] | None = None,
             executor_factory: Callable[[], Executor] = SingleThreadedExecutor) -> None:
    """Run ``node_class()`` on ``executor_factory()`` until SIGINT/SIGTERM, then stop cleanly."""
    signals = SignalShutdown()  # before rclpy.init: no window with rclpy's handlers
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = create_node_or_exit(node_class)
    signals.attach(node)
    executor = executor_factory()
    executor.add_node(node)
    try:
        executor.spin()
    except ExternalShutdownException:  # the signal's guard shut the context down
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
