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
then has 10 intervals (200 ms) to take its answer before 10 others could push it out, and a
burst of N requests is answered within N intervals (50: 1 s) plus the one fit.

A second way to lose an answer: rmw_fastrtps sends it only once the server has matched the
client's response reader, waiting at most 100 ms, and otherwise drops it with only a
``RuntimeWarning: failed to send response (timeout)``. A server that has just (re)started
meets clients it has not discovered yet (a respawned tuner, a client that found the old one).
Such an answer is retried every ``RETRY_S`` for at most ``RETRY_FOR_S``.
"""

from __future__ import annotations

import threading
import time
import warnings

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.service import Service

ANSWER_INTERVAL_S = 0.02
RETRY_S = 0.05
RETRY_FOR_S = 10.0
# Only sends made from this module raise instead of warning: the filter matches the module a
# warning is attributed to, the caller of the C extension, i.e. this one.
warnings.filterwarnings('error', message='failed to send response', category=RuntimeWarning,
                        module=__name__)


def pace_answers(service: Service, interval_s: float = ANSWER_INTERVAL_S) -> Service:
    """Make ``service`` send at most one answer per ``interval_s``; return the service."""
    lock = threading.Lock()

    def send(response, header) -> None:
        request_id = (header.request_id if isinstance(header, _rclpy.rmw_service_info_t)
                      else header)
        deadline = time.monotonic() + RETRY_FOR_S
        while True:
            try:
                with service.handle:
                    service.handle.service_send_response(response, request_id)
                return
            except RuntimeWarning:  # the client is not matched yet: retry, then give up
                if time.monotonic() >= deadline:
                    return
                time.sleep(RETRY_S)

    next_send = [0.0]

    def paced_send_response(response, header) -> None:
        with lock:  # the executor's threads answer one after the other, interval_s apart
            delay = next_send[0] - time.monotonic()
            if delay > 0.0:
                time.sleep(delay)
            send(response, header)
            next_send[0] = time.monotonic() + interval_s

    # The executor sends through this attribute: the instance's own shadows the method.
    service.send_response = paced_send_response  # type: ignore[method-assign]
    return service
