# SPDX-License-Identifier: Apache-2.0
"""
`ros2 launch` signals its nodes without taking their exit codes from asyncio's child watcher.

launch stops a node through its asyncio subprocess transport (``transport.send_signal``, and
``kill`` for SIGKILL): the SIGINT of a noninteractive ``ros2 launch`` (stdin not a terminal),
the SIGTERM and SIGKILL of its escalation, a ``SignalProcess``. Before CPython 3.13 the
transport hands that to ``subprocess.Popen.send_signal``, which first polls the process:
``waitpid(pid, WNOHANG)``. A node that has exited already (a Ctrl-C reaches the whole process
group; our nodes end on it at once) but whose exit the watcher's thread has not collected yet (a
loaded machine keeps that thread off the CPU) is reaped by that poll; the thread's own
``waitpid`` then fails and asyncio reports exit code 255 ("Unknown child process pid N, will
report returncode 255"): launch logs a clean stop as "process has died ... exit code 255".

``signal_children_without_reaping`` makes the transports signal with ``os.kill`` alone, as
CPython 3.13 does: a signal to an exited, not yet collected node reaches a zombie and does
nothing, and the watcher reports the node's own exit code. Once the watcher has reported it
the transport sends nothing (the pid may be another process's by then); between the watcher's
``waitpid`` and that report a signal could reach a reused pid, as under CPython 3.13.
"""

from __future__ import annotations

from asyncio.base_subprocess import BaseSubprocessTransport
import os
import signal
import sys

# The first CPython whose subprocess transports signal with kill() and never poll.
_SIGNALS_WITHOUT_POLLING = (3, 13)


def _send_signal(transport: BaseSubprocessTransport, signum: int) -> None:
    if transport.get_returncode() is not None:
        return  # collected: the pid is no longer the node's
    pid = transport.get_pid()
    if pid is None:
        raise ProcessLookupError('the process has not started')
    try:
        os.kill(pid, signum)
    except ProcessLookupError:
        pass  # collected since the check above


def _terminate(transport: BaseSubprocessTransport) -> None:
    _send_signal(transport, signal.SIGTERM)


def _kill(transport: BaseSubprocessTransport) -> None:
    _send_signal(transport, signal.SIGKILL)


def signal_children_without_reaping() -> bool:
    """
    Make asyncio's subprocess transports signal with ``os.kill``, never ``waitpid``.

    For the launch process (the launch file calls it); only on POSIX before CPython 3.13, where
    the transports poll before they signal. Return whether the transports signal so now.
    """
    if os.name != 'posix':
        return False
    if sys.version_info >= _SIGNALS_WITHOUT_POLLING:
        return True
    setattr(BaseSubprocessTransport, 'send_signal', _send_signal)
    setattr(BaseSubprocessTransport, 'terminate', _terminate)
    setattr(BaseSubprocessTransport, 'kill', _kill)
    return True
