"""
Ctrl-C and SIGTERM stop a node between two callbacks, never in the middle of one.

With rclpy's own signal handling, a signal either raises KeyboardInterrupt wherever the main
thread is (inside a pybind11 call that surfaces as ``RuntimeError: Unable to convert call
argument ...``) or shuts the context down from rclpy's signal thread while a callback runs (its
``publish`` then raises RCLError). Both end the node with exit 1 and a trace; both were seen when
a busy node was interrupted. ``SignalShutdown`` replaces that: the C-level signal handler only
writes to a socket (``signal.set_wakeup_fd``), a watcher thread wakes on it and triggers a guard
condition of the node, and the executor runs that guard's callback like any other, between the
others: it shuts the context down, so ``rclpy.spin`` returns (or raises
ExternalShutdownException, which the Jazzy ``main()`` idiom catches).

In ``main()``: ``SignalShutdown()`` and then ``rclpy.init(..., signal_handler_options=
SignalHandlerOptions.NO)``; ``attach(node)`` once the node exists. A signal that arrives before
``attach`` is kept and acted on as soon as the node is attached.
"""

from __future__ import annotations

import signal
import socket
import threading


class SignalShutdown:
    """Turns SIGINT/SIGTERM into an rclpy shutdown run by the executor's own loop."""

    def __init__(self) -> None:
        """Route both signals to a watcher thread (call from the main thread)."""
        self.requested = False
        self._guard = None
        self._receiver, sender = socket.socketpair()
        sender.setblocking(False)
        self._sender = sender  # kept open for the life of the process
        signal.set_wakeup_fd(sender.fileno())
        for signum in (signal.SIGINT, signal.SIGTERM):
            # A Python handler must exist for the wakeup fd to be written; it does nothing.
            signal.signal(signum, lambda _signum, _frame: None)
        threading.Thread(target=self._watch, name='signals', daemon=True).start()

    def attach(self, node) -> None:
        """Give ``node`` the guard condition that shuts rclpy down once a signal came."""
        import rclpy

        self._guard = node.create_guard_condition(lambda: rclpy.try_shutdown())
        if self.requested:
            self._guard.trigger()

    def _watch(self) -> None:
        while self._receiver.recv(64):
            self.requested = True
            if self._guard is not None:
                self._guard.trigger()
