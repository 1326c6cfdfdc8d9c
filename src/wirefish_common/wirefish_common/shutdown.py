# SPDX-License-Identifier: Apache-2.0
"""
Ctrl-C and SIGTERM stop a process between two callbacks, never in the middle of one.

With rclpy's own signal handling, a signal either raises KeyboardInterrupt wherever the main
thread is (inside a pybind11 call that surfaces as ``RuntimeError: Unable to convert call
argument ...``) or shuts the context down from rclpy's signal thread while a callback runs (its
``publish`` then raises RCLError). Both end the node with exit 1 and a trace; both were seen when
a busy node was interrupted. ``SignalShutdown`` replaces that: the C-level signal handler only
writes to a socket (``signal.set_wakeup_fd``), a watcher thread wakes on it and triggers a guard
condition of the node, and the executor runs that guard's callback like any other, between the
others: it shuts the context down, so the executor's spin returns.

However many signals arrive, the process stops once and exits 0:

- a signal that arrives while the node is being destroyed finds its guard condition gone
  (rclpy's ``InvalidHandle``): the stop is already under way, so it is dropped;
- Python's own finalisation puts the default action (die of the signal: exit -2 / -15) back on
  every signal that has a Python handler, so a late Ctrl-C would kill a process that had
  already stopped cleanly; from ``atexit`` on, SIGINT and SIGTERM are ignored instead.

Nodes use it through ``wirefish_common.node_main.run_node``, which spins with
``wirefish_common.executors.spin_until_stopped`` and hands its executor to ``attach_executor``:
the events executor supports no guard condition, so there a signal sets ``requested`` and wakes
the executor with a no-op task, and the loop ends between two callbacks (the same on the classic
executor). ``attach(node)`` (a guard condition that shuts rclpy down) is for processes that
call ``spin()`` on a classic executor. Processes without a node to attach (a loop of their own)
poll ``requested``. A signal that arrives before ``attach``/``attach_executor`` is kept and
acted on as soon as one is called.

A process still running ``STOP_STACKS_AFTER_S`` after the first signal writes the stacks of all
its threads to stderr (its log under `wirefish up`), before the launcher's deadline
(``wirefish_launcher.verb.up``) escalates to SIGTERM and SIGKILL: a stop that hangs then says
where it hangs. A process that stops in time writes nothing (the interpreter cancels the dump at
exit).
"""

from __future__ import annotations

import atexit
import faulthandler
import os
import signal
import socket
import sys
import threading
from typing import Any, NoReturn

from wirefish_common.startup_signals import release_stop_signals, STOP_SIGNALS
# Under the 6 s `wirefish up` gives a graph of 6 processes to stop; a stop takes < 2 s on the
# loaded 2-core reference machine (load average 10).
STOP_STACKS_AFTER_S = 4.0
# The longest a process's teardown (destroy_node, executor, context) may take once its loop has
# stopped: before the launcher's SIGKILL (SIGTERM at 1 s per process, at least 5 s, which a
# stopping process ignores; SIGKILL 2 s later), over what teardowns took at load 100 (8 graphs
# at once on 2 cores: with 2 s and 4 s bounds, teardowns that would have finished ended as 1).
TEARDOWN_S = 6.0


def begin_teardown(seconds: float = TEARDOWN_S) -> None:
    """
    Start the teardown after a process's loop has stopped: its threads on one CPU, a time bound.

    One CPU: Fast DDS 2.14 deletes a participant (rclpy's ``destroy_node`` of a process's last
    node) through ``DomainParticipant::set_listener(nullptr)``, which waits for a discovery
    callback in flight with an infinite timeout that libstdc++ turns into a busy loop holding
    the participant's listener mutex (eProsima/Fast-DDS#6513). The callback's thread needs that
    mutex to finish, and woken on the other core it met the mutex taken again almost every
    time: when a graph stops, every process's departure is such a callback in the others, and
    2 of 20 stops of a fleet of three beside two busy loops had a node spinning there until the
    launcher's SIGKILL (gdb: the main thread in ``set_listener`` under ``rcl_node_fini``, a DDS
    receive thread in the listener's ``onWriterDiscovery`` waiting for the mutex). On the
    spinning thread's CPU, the woken thread runs when the spinning one gives the mutex up: 0 of
    30 such stops, 540 teardowns, the longest 0.35 s. Measure with ``tools/wfenv python
    tools/probes/sigint_soak.py --runs 20 --fleet 3 --swim-s 20 --bound 6`` beside the load.

    The bound: a process still here ``seconds`` on ends with its threads' stacks and exit code 1.
    A DDS teardown that never returns may hold the GIL, so no Python thread could end it:
    faulthandler's own C thread can. A process that finishes in time leaves through
    ``exit_now``, which ends the timer with the process.
    """
    threads_on_one_cpu()
    faulthandler.dump_traceback_later(seconds, exit=True)


def threads_on_one_cpu() -> dict[int, set[int]]:
    """
    Let every thread of this process run on one CPU only (the first it may use); Linux.

    Returns the CPUs each thread could use before, for ``restore_cpus``.
    """
    if not hasattr(os, 'sched_setaffinity'):
        return {}
    cpu = min(os.sched_getaffinity(0))
    before: dict[int, set[int]] = {}
    for task in os.listdir('/proc/self/task'):
        try:
            before[int(task)] = os.sched_getaffinity(int(task))
            os.sched_setaffinity(int(task), {cpu})
        except OSError:  # the thread has just ended
            pass
    return before


def restore_cpus(before: dict[int, set[int]]) -> None:
    """Give each thread the CPUs ``threads_on_one_cpu`` took; a newer one, the calling one's."""
    if not before:
        return
    default = before.get(threading.get_native_id(), set().union(*before.values()))
    for task in os.listdir('/proc/self/task'):
        try:
            os.sched_setaffinity(int(task), before.get(int(task), default))
        except OSError:  # the thread has just ended
            pass


def ignore_stop_signals() -> None:
    """Ignore SIGINT and SIGTERM from now on (the process is on its way out)."""
    for signum in STOP_SIGNALS:
        signal.signal(signum, signal.SIG_IGN)


class SignalShutdown:
    """Turns SIGINT/SIGTERM into an rclpy shutdown run by the executor's own loop."""

    def __init__(self, stacks_after_s: float = STOP_STACKS_AFTER_S) -> None:
        """Route both signals to a watcher thread (call from the main thread)."""
        self.requested = False
        self._stacks_after_s = stacks_after_s
        self._guard: Any = None
        self._executor: Any = None
        self._executor_lock = threading.Lock()  # a wake never meets an executor shut down
        self._receiver, sender = socket.socketpair()
        sender.setblocking(False)
        self._sender = sender  # kept open for the life of the process
        # A full buffer only means signals are already waiting to be read: nothing to report.
        signal.set_wakeup_fd(sender.fileno(), warn_on_full_buffer=False)
        for signum in STOP_SIGNALS:
            # A Python handler must exist for the wakeup fd to be written; it does nothing.
            signal.signal(signum, lambda _signum, _frame: None)
        atexit.register(ignore_stop_signals)
        threading.Thread(target=self._watch, name='signals', daemon=True).start()
        release_stop_signals()  # one held since the process started arrives now, as any other

    def attach(self, node: Any) -> None:
        """Give ``node`` the guard condition that shuts rclpy down once a signal came."""
        import rclpy

        self._guard = node.create_guard_condition(lambda: rclpy.try_shutdown())
        if self.requested:
            self._trigger()

    def attach_executor(self, executor: Any) -> None:
        """
        Wake ``executor`` once a signal came (its spin loop stops on ``requested``).

        ``attach_executor(None)`` before shutting the executor down: a later signal then wakes
        nothing (a classic executor refuses tasks once shut down).
        """
        with self._executor_lock:
            self._executor = executor
        if self.requested:
            self._trigger()

    def _watch(self) -> None:
        while self._receiver.recv(64):
            if not self.requested:
                # The dump goes to fd 2 from faulthandler's own C thread: it works while the
                # main thread hangs in C code too.
                faulthandler.dump_traceback_later(self._stacks_after_s, exit=False)
            self.requested = True
            self._trigger()

    def _trigger(self) -> None:
        from rclpy.exceptions import InvalidHandle

        with self._executor_lock:
            if self._executor is not None:
                from wirefish_common.executors import wake
                wake(self._executor)
        guard = self._guard
        if guard is None:
            return
        try:
            guard.trigger()
        except InvalidHandle:  # the node is being destroyed: its stop is already under way
            pass


def exit_now(code: int) -> NoReturn:
    """
    End the process with ``code`` now, once everything it owns is stopped and destroyed.

    What is left after a node's clean stop is the interpreter's finalisation: module teardown
    and a full garbage collection of every object rclpy, numpy and the node made. On a loaded
    machine that was most of a stop (perf: ``gc_collect_main``; at load 60-90 every node of a
    graph was still finalising when `ros2 launch` killed it ~13 s after Ctrl-C), and Python
    ignores SIGTERM from atexit on. Late signals are ignored, Python's logging handlers and
    stdout/stderr are flushed (rclpy's log file is closed by its ``try_shutdown``), then
    ``os._exit``.
    """
    ignore_stop_signals()
    if 'logging' in sys.modules:
        sys.modules['logging'].shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed or broken pipe: nothing left to say there
            pass
    os._exit(code)
