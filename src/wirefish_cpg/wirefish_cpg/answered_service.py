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
"""

from __future__ import annotations

import threading
import time

from rclpy.service import Service

ANSWER_INTERVAL_S = 0.02


def pace_answers(service: Service, interval_s: float = ANSWER_INTERVAL_S) -> Service:
    """Make ``service`` send at most one answer per ``interval_s``; return the service."""
    send = service.send_response
    lock = threading.Lock()
    next_send = [0.0]

    def paced_send_response(response, header) -> None:
        with lock:  # the executor's threads answer one after the other, interval_s apart
            delay = next_send[0] - time.monotonic()
            if delay > 0.0:
                time.sleep(delay)
            send(response, header)
            next_send[0] = time.monotonic() + interval_s

    service.send_response = paced_send_response  # the executor sends through this attribute
    return service
