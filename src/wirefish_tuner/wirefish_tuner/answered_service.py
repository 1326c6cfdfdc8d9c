# SPDX-License-Identifier: Apache-2.0
"""
Service answers paced so that a burst of requests is answered every one (ROS 2 Jazzy, DDS).

Why answers of a burst were lost: a service's answers all go out on one DDS topic, and every
client's response reader receives every answer, its own and everyone else's, and keeps the last
10 (rclpy's default service QoS, KEEP_LAST 10); the rmw throws the others' away only when the
client takes them. Twenty "busy" answers sent within a millisecond overwrite a client's own
answer before its executor takes it: 20 requests at once left 6-10 unanswered, 50 clients at
once 29 (measured; with 3 s between discovery and the burst, or with clients keeping 1000
answers, none is lost). The server cannot deepen its clients' queues (`ros2 service call` uses
the default), so it paces its answers instead: at most one per ``ANSWER_INTERVAL_S``. A client
then has 10 intervals (200 ms) to take its answer before 10 others could push it out.

The pacing is done in the callback, through rclpy's public API only: the executor sends what a
callback returns right after it returns, so a callback that returns no sooner than
``interval_s`` after the previous one returned spaces the answers. The work itself (a fit) runs
outside the pacing lock; only the wait for the next slot is serialised, and it holds an
executor thread at most ``interval_s`` per answer queued ahead of it.

An answer can also be dropped when the server has not matched the client's response reader yet
(a server that has just started, a client just created): the workspace's Fast DDS profile
(wirefish_bringup config/fastdds.xml) makes the reply writer wait for that match instead.
"""

from __future__ import annotations

import threading
import time
from typing import Callable, TypeVar

ANSWER_INTERVAL_S = 0.02

Request = TypeVar('Request')
Response = TypeVar('Response')


class AnswerPacer:
    """Hands out answer slots at least ``interval_s`` apart (clock and sleep are passed in)."""

    def __init__(self, interval_s: float = ANSWER_INTERVAL_S,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        """Start with the first slot free."""
        self.interval_s = interval_s
        self._clock = clock
        self._sleep = sleep
        self._lock = threading.Lock()
        self._next = float('-inf')

    def wait_for_slot(self) -> None:
        """Return once this answer may go out: ``interval_s`` after the previous one."""
        with self._lock:
            delay = self._next - self._clock()
            if delay > 0.0:
                self._sleep(delay)
            self._next = self._clock() + self.interval_s


def paced(callback: Callable[[Request, Response], Response],
          pacer: AnswerPacer | None = None) -> Callable[[Request, Response], Response]:
    """Return a service callback that answers as ``callback`` does, its answers paced."""
    slots = AnswerPacer() if pacer is None else pacer

    def answer(request: Request, response: Response) -> Response:
        result = callback(request, response)
        slots.wait_for_slot()
        return result
    return answer
