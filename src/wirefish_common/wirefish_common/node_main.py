# SPDX-License-Identifier: Apache-2.0
"""
The one ``main()`` of every wirefish node: signals, rclpy, the node, its executor, a clean stop.

``run_node(CpgNode, args)`` is the whole of a node module's ``main()``:

1. SIGINT/SIGTERM are routed through ``SignalShutdown`` before ``rclpy.init`` (rclpy's own
   handlers are off), so a signal stops the node between two callbacks, however many arrive;
2. the node is built; start-up values it refuses (``InvalidParameters``, including a value of
   the wrong type) end the process with one FATAL line and exit code 1, no traceback;
3. the executor (``executor_factory()``; by default the one ``WIREFISH_EXECUTOR`` names, the
   events executor unless it says ``classic``: ``wirefish_common.executors``) spins one
   callback at a time until a signal; a ``WIREFISH_EXECUTOR`` that names no executor ends the
   process with one FATAL line and exit code 1;
4. the node leaves the executor (one spin lets the events executor release it) and is
   destroyed (its threads joined), so it leaves the graph at once, its participant a moment
   later (``graph_exit``: so that it stays gone); then the context is shut down; the process
   then ends with exit code 0 at once (``exit_now``), without the interpreter's own
   finalisation.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import rclpy
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from wirefish_common.executors import (executor_kind, make_executor, settle,
                                       spin_until_stopped)
from wirefish_common.graph_exit import destroy_leaving_the_graph
from wirefish_common.parameter_table import InvalidParameters
from wirefish_common.shutdown import begin_teardown, exit_now, SignalShutdown

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


def chosen_executor_factory() -> Callable[[], Executor]:
    """Return a factory of the executor ``WIREFISH_EXECUTOR`` names; FATAL line, exit 1 if none."""
    try:
        kind = executor_kind()
    except ValueError as error:
        rclpy.logging.get_logger('wirefish').fatal(str(error))
        rclpy.try_shutdown()
        raise SystemExit(1) from None
    return lambda: make_executor(kind)


def run_node(node_class: Callable[[], Node], args: list[str] | None = None,
             executor_factory: Callable[[], Executor] | None = None) -> None:
    """Run ``node_class()`` on ``executor_factory()`` until SIGINT/SIGTERM, then stop cleanly."""
    signals = SignalShutdown()  # before rclpy.init: no window with rclpy's handlers
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    factory = executor_factory or chosen_executor_factory()
    if signals.requested:  # a stop while rclpy started: no node to build, nothing to undo
        rclpy.try_shutdown()
        exit_now(0)
    node = create_node_or_exit(node_class)
    executor = factory()
    executor.add_node(node)
    signals.attach_executor(executor)
    try:
        spin_until_stopped(executor, lambda: signals.requested)
    except ExternalShutdownException:  # the context was shut down under the loop
        pass
    finally:
        signals.attach_executor(None)
        begin_teardown()
        # The node's own threads (serial reader, publish loop) are joined by destroy_node
        # before the executor goes: a task they hand over meets a live executor.
        executor.remove_node(node)
        # The events executor lets go of a removed node's entities in a handler it queues
        # behind the callbacks already waiting: until that has run, destroy_node cannot
        # destroy the node, and without that the node stays in every other participant's
        # graph (`ros2 node list`) until this participant's lease runs out, ~20 s after the
        # exit. One spin_once ran a waiting callback instead on a loaded machine: settle
        # spins until a task queued after the removal has run.
        try:
            settle(executor)
        except (ExternalShutdownException, RuntimeError):  # the context is already shut down
            pass
        destroy_leaving_the_graph(node)
        # No executor.shutdown(): exit_now follows, and what it would free the exit frees. Its
        # teardown of the removed node's entities (the events executor's, with the GIL held)
        # was seen to hang: bridge_node's main thread in executor.shutdown() until the 6 s
        # teardown bound, in one of three bridges of a fleet's stop.
        rclpy.try_shutdown()
    exit_now(0)
