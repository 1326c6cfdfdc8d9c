# SPDX-License-Identifier: Apache-2.0
"""Watch the ROS graph: which nodes run, and every topic's rate (`ros2 topic hz` for all)."""

from collections.abc import Callable
import time

from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from wirefish_common.topics import graph_topics, matching_qos, message_class


def _never() -> bool:
    return False


def discovered_nodes(node: Node) -> set[str]:
    """Return the fully qualified names of the nodes ``node`` discovers now."""
    return {f'{ns.rstrip("/")}/{name}' for name, ns in node.get_node_names_and_namespaces()}


def registry_nodes_present(node: Node, executor: SingleThreadedExecutor, namespace: str,
                           names: list[str], listen_s: float,
                           should_stop: Callable[[], bool] = _never) -> list[str]:
    """
    Return which of ``names`` already run in ``namespace`` (sorted), listening ``listen_s``.

    Answers as soon as one is discovered; an empty list after ``listen_s`` (or a true
    ``should_stop()``) means none was.
    """
    wanted = {f'{namespace.rstrip("/")}/{name}': name for name in names}
    deadline = time.monotonic() + listen_s
    while True:
        present = sorted(wanted[fq] for fq in discovered_nodes(node) & wanted.keys())
        if present or time.monotonic() >= deadline or should_stop():
            return present
        executor.spin_once(timeout_sec=0.1)


def settle_discovery(node: Node, executor: SingleThreadedExecutor, namespace: str,
                     quiet_s: float = 1.5, timeout_s: float = 10.0,
                     should_stop: Callable[[], bool] = _never) -> None:
    """
    Spin until the graph's topic set has not changed for ``quiet_s`` (or ``timeout_s``).

    Returns early as soon as ``should_stop()`` is true (a Ctrl-C of the caller).
    """
    start = changed = time.monotonic()
    seen = graph_topics(node, namespace)
    while time.monotonic() - start < timeout_s and not should_stop():
        executor.spin_once(timeout_sec=0.25)
        now = graph_topics(node, namespace)
        if now != seen:
            seen, changed = now, time.monotonic()
        elif seen and time.monotonic() - changed >= quiet_s:
            return


def measure_rates(node: Node, executor: SingleThreadedExecutor, namespace: str,
                  window_s: float, should_stop: Callable[[], bool] = _never
                  ) -> dict[str, tuple[str, float]]:
    """
    Return {topic: (type, messages per second)} received over ``window_s`` seconds.

    A true ``should_stop()`` ends the window early (the rates are then over what was seen).
    """
    topics = graph_topics(node, namespace)
    counts = dict.fromkeys(topics, 0)
    subscriptions = []
    for topic, type_name in topics.items():
        def count(_data: bytes, topic: str = topic) -> None:
            counts[topic] += 1
        try:
            msg_class = message_class(type_name)
        except (ImportError, AttributeError, ValueError):
            continue
        subscriptions.append(node.create_subscription(
            msg_class, topic, count, matching_qos(node, topic, 100), raw=True))
    # Let the subscriptions match their publishers (and latched samples arrive) before counting.
    settle_until = time.monotonic() + 0.5
    while time.monotonic() < settle_until and not should_stop():
        executor.spin_once(timeout_sec=0.05)
    counts = dict.fromkeys(topics, 0)
    start = time.monotonic()
    while time.monotonic() - start < window_s and not should_stop():
        executor.spin_once(timeout_sec=0.05)
    elapsed = max(time.monotonic() - start, 1e-9)
    for subscription in subscriptions:
        node.destroy_subscription(subscription)
    return {topic: (topics[topic], counts[topic] / elapsed) for topic in sorted(topics)}


class StreamLog:
    """
    When each message of some topics arrived (monotonic seconds), from creation on.

    Subscribes best effort, which matches reliable and best-effort publishers alike, and keeps
    the raw bytes only of the ``keep`` topics (to read what was sent, not just when).
    """

    def __init__(self, node: Node, topics: dict[str, type], keep: tuple[str, ...] = ()) -> None:
        """Subscribe to every topic of ``topics`` ({full name: message class})."""
        from rclpy.qos import qos_profile_sensor_data

        self.arrivals: dict[str, list[float]] = {topic: [] for topic in topics}
        self.kept: dict[str, list[tuple[float, bytes]]] = {topic: [] for topic in keep}
        for topic, msg_class in topics.items():
            def on_message(data: bytes, topic: str = topic) -> None:
                now = time.monotonic()
                self.arrivals[topic].append(now)
                if topic in self.kept:
                    self.kept[topic].append((now, data))
            node.create_subscription(msg_class, topic, on_message, qos_profile_sensor_data,
                                     raw=True)

    def rate(self, topic: str, since: float, until: float) -> float:
        """Return the messages per second of ``topic`` that arrived in [since, until]."""
        return rate_between(self.arrivals[topic], since, until)

    def longest_pause(self, topic: str, since: float, until: float) -> float:
        """Return the longest time in [since, until] without a message of ``topic``."""
        return longest_pause(self.arrivals[topic], since, until)


def rate_between(times: list[float], since: float, until: float) -> float:
    """Return how many of ``times`` fall in [since, until], per second."""
    return sum(since <= t <= until for t in times) / max(until - since, 1e-9)


def longest_pause(times: list[float], since: float, until: float) -> float:
    """Return the longest gap in [since, until] between ``times`` (or an end of the span)."""
    inside = [t for t in times if since <= t <= until]
    edges = [since, *inside, until]
    return max(b - a for a, b in zip(edges, edges[1:]))
