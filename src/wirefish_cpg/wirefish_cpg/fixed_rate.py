# SPDX-License-Identifier: Apache-2.0
"""
A fixed-rate loop on its own thread: calls a function at absolute deadlines (pure, no rclpy).

Why not an rclpy timer: at 1 kHz the Python executor's per-wake work (rebuilding the wait set of
every service, timer and event of the node) costs far more than the CPG step and the publish
(profiled: about 90 % of the CPG node's CPU was executor overhead). This loop sleeps straight to
the next deadline, so the node's executor only wakes for services and parameter changes.

Deadlines are absolute (period n at start + n * period), so there is no drift; a tick that is
more than a whole period late skips the missed deadlines (counted in ``missed``) instead of
firing a burst, as ROS timers do.

Why a tick is late, and what the loop does about each cause:
- the OS runs other work when the deadline comes (a loaded machine: p99 2.4 ms of lateness at
  100 Hz with an idle main thread, 2 cores at load 48). The loop thread asks for SCHED_FIFO at
  the lowest real-time priority, so it runs as soon as it wakes (p99 0.25 ms in the same
  conditions); without the privilege (CAP_SYS_NICE or an RLIMIT_RTPRIO) it keeps the default
  policy and ``scheduling`` says why;
- another thread of the process holds the GIL (the executor running a callback): a thread that
  wants it waits up to the switch interval (5 ms by default) before the holder is asked to let
  go. The loop lowers the interval to ``GIL_SWITCH_INTERVAL_S`` for the process (a callback
  shorter than that is never interrupted, so the cost is nil while the GIL is not contended);
- the wake-up itself: timer slack 1 us (below), absolute deadlines.
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import os
import sys
import threading
import time

PR_SET_TIMERSLACK = 29  # prctl option (Linux): the thread's timer slack in ns
TIMER_SLACK_NS = 1000  # the default 50 us would be a quarter of a 1 kHz p99 jitter budget
# The longest another thread keeps the GIL once the loop wants it: a fifth of a 1 kHz period.
GIL_SWITCH_INTERVAL_S = 0.0002
REALTIME_PRIORITY = 1  # the lowest SCHED_FIFO priority: above every normal thread, nothing more


def _realtime_scheduling() -> str:
    """Put the calling thread on SCHED_FIFO if allowed; return the policy it runs with."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
    except (OSError, AttributeError) as error:  # no privilege, or not Linux
        return f'default (SCHED_FIFO refused: {error})'
    return f'SCHED_FIFO {REALTIME_PRIORITY}'


def _tighten_timer_slack() -> None:
    """Ask Linux to wake this thread within 1 us of its deadline; elsewhere do nothing."""
    try:
        ctypes.CDLL(None).prctl(PR_SET_TIMERSLACK, TIMER_SLACK_NS, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the default slack is still correct
        pass


class FixedRateLoop:
    """Calls ``tick()`` every ``period_s`` seconds on a daemon thread until ``stop()``."""

    def __init__(self, period_s: float, tick: Callable[[], None], name: str) -> None:
        """Prepare the loop (not started); ``period_s`` > 0 s."""
        self.period_s = period_s
        self.missed = 0
        self.scheduling = 'not started'  # the loop thread's policy once it runs
        self._tick = tick
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    @property
    def period_s(self) -> float:
        """Return the period (s); a new one takes effect from the next deadline."""
        return self._period_s

    @period_s.setter
    def period_s(self, value: float) -> None:
        if not value > 0.0:
            raise ValueError(f'period must be > 0 s, got {value}')
        self._period_s = float(value)

    def start(self) -> None:
        """Start calling ``tick`` (first call one period from now)."""
        self._thread.start()

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop the loop and wait for its thread (a running tick finishes first)."""
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout_s)

    def _run(self) -> None:
        _tighten_timer_slack()
        sys.setswitchinterval(min(sys.getswitchinterval(), GIL_SWITCH_INTERVAL_S))
        self.scheduling = _realtime_scheduling()
        deadline = time.monotonic()
        while not self._stop.is_set():
            period = self._period_s
            deadline += period
            delay = deadline - time.monotonic()
            if delay > 0.0:
                if self._stop.wait(delay):
                    break
            elif -delay > period:
                skipped = int(-delay // period)
                self.missed += skipped
                deadline += skipped * period
            self._tick()
