"""
A Ctrl-C while a node's process is still importing is kept, not a KeyboardInterrupt trace.

A node's process spends its first second or more importing (rclpy, numpy, the messages)
before ``SignalShutdown`` is installed; Python's default SIGINT handler then raised
KeyboardInterrupt in the middle of an import: a traceback and exit -2. The package of each
node executable calls ``hold_stop_signals_for`` from its ``__init__`` (the first of its modules
any entry point imports), which, only in a process started as one of those executables, makes
SIGINT and SIGTERM be recorded in ``received`` instead; ``SignalShutdown`` takes them over as a
stop request, so the node stops at once after start-up with exit code 0. A process that
imports the package for another reason (a test, a tool) keeps its own handlers.

What is left: the interpreter's own start-up and the entry-point script's imports before the
package (``importlib.metadata``), tens of milliseconds on a quiet machine.
"""

from __future__ import annotations

import os
import signal
import sys

received: list[int] = []  # the signals that arrived before SignalShutdown took over


def _keep(signum: int, _frame: object) -> None:
    received.append(signum)


def hold_stop_signals_for(*executables: str) -> None:
    """Record SIGINT/SIGTERM in ``received`` if this process runs one of ``executables``."""
    if os.path.basename(sys.argv[0] if sys.argv else '') in executables:
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, _keep)
