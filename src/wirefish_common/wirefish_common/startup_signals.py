# SPDX-License-Identifier: Apache-2.0
"""
A Ctrl-C while a node's process is still importing ends it with exit 0, not with a trace.

A node's process spends its first second or more importing (rclpy, numpy, the messages)
before ``SignalShutdown`` is installed; Python's default SIGINT handler would raise
KeyboardInterrupt in the middle of an import: a traceback and exit -2. Each executable's entry
point (the function ``console_scripts`` names, in its package's ``executables`` module) calls
``hold_stop_signals`` before it imports its node's module: from then on SIGINT and SIGTERM end
the process at once with exit code 0 (``_end_at_once``) until ``SignalShutdown`` takes them over:
nothing of the node exists yet (no DDS participant, no file), so that is the whole of a clean
stop, without waiting for the rest of the imports (on a loaded machine they alone outlast
`ros2 launch`'s 5 s before it escalates to SIGTERM). Importing a package changes no handler:
only a process started as one of the executables holds its stops.

That leaves the interpreter's own start-up and the entry-point script's imports before the
entry point runs (``importlib.metadata``): tens of milliseconds in which nothing of ours runs
yet. A launcher closes them: it starts the process with both signals blocked
(``block_stop_signals`` between fork and exec; a blocked signal stays pending across exec),
and the process releases them (``release_stop_signals``) once its own handler is in place,
from ``hold_stop_signals``, ``SignalShutdown`` or a handler of its own; a signal that came
meanwhile is delivered then, to that handler. `wirefish up` starts every process of the
registry so; the launch file starts them through ``held_start_prefix`` (coreutils' ``env``
blocking both before it execs the node). A process started with the default disposition
(`ros2 run`) keeps the window.
"""

from __future__ import annotations

import os
import signal

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
# coreutils >= 8.31 (Ubuntu 24.04: 9.4): env resets their action, blocks them, execs the node
# (in this order: coreutils 9.1 forgets the block when --default-signal follows it).
_HELD_START = ('--default-signal=INT,TERM', '--block-signal=INT,TERM')


def _end_at_once(_signum: int, _frame: object) -> None:
    os._exit(0)  # still importing: nothing to stop but the process (see the docstring)


def block_stop_signals() -> None:
    """
    Block SIGINT and SIGTERM, with their default action (a launcher's child, fork to exec).

    The default action, because an ignored signal is discarded even while blocked, and a
    launcher started from a background job of a shell inherits SIGINT ignored.
    """
    signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)
    for signum in STOP_SIGNALS:
        signal.signal(signum, signal.SIG_DFL)


def release_stop_signals() -> None:
    """Unblock SIGINT and SIGTERM: one that is pending is delivered to the handler now."""
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)


def hold_stop_signals() -> None:
    """
    End the process on SIGINT/SIGTERM from now on, and release them if a launcher held them.

    For an executable's entry point, before it imports its node: until ``SignalShutdown`` (or
    the process's own handler) is in place, a stop ends the process at once, exit code 0.
    """
    for signum in STOP_SIGNALS:
        signal.signal(signum, _end_at_once)
    release_stop_signals()


def stop_signals_blocked(proc_status: str) -> bool:
    """Whether a ``/proc/<pid>/status`` text shows SIGINT and SIGTERM both blocked."""
    masks = [line.split()[1] for line in proc_status.splitlines() if line.startswith('SigBlk:')]
    blocked = int(masks[0], 16) if masks else 0
    return all(blocked >> (signum - 1) & 1 for signum in STOP_SIGNALS)


def held_start_prefix() -> str | None:
    """
    Return a command prefix that starts a process with SIGINT/SIGTERM blocked, for launch_ros.

    None where this machine's ``env`` cannot (no coreutils, one older than 8.31, or one whose
    block does not reach the command: checked on a process started through it): the process
    then starts with the default disposition, as without a prefix.
    """
    import shlex
    import shutil
    import subprocess

    env = shutil.which('env')
    if env is None:
        return None
    try:
        status = subprocess.run([env, *_HELD_START, 'cat', '/proc/self/status'], check=True,
                                capture_output=True, text=True, timeout=10.0).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    if not stop_signals_blocked(status):
        return None
    return shlex.join([env, *_HELD_START])
