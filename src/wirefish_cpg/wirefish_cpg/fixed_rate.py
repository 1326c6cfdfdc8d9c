"""
A fixed-rate loop on its own thread: calls a function at absolute deadlines (pure, no rclpy).

Why not an rclpy timer: at 1 kHz the Python executor's per-wake work (rebuilding the wait set of
every service, timer and event of the node) costs far more than the CPG step and the publish
(profiled: about 90 % of the CPG node's CPU was executor overhead). This loop sleeps straight to
the next deadline, so the node's executor only wakes for services and parameter changes.

Deadlines are absolute (period n at start + n * period), so there is no drift; a tick that is
more than a whole period late skips the missed deadlines (counted in ``missed``) instead of
firing a burst, as ROS timers do.
"""

from __future__ import annotations

from collections.abc import Callable
import ctypes
import threading
import time

PR_SET_TIMERSLACK = 29  # prctl option (Linux): the thread's timer slack in ns
TIMER_SLACK_NS = 1000  # the default 50 us would be a quarter of a 1 kHz p99 jitter budget


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
