# SPDX-License-Identifier: Apache-2.0
"""`wirefish topic echo|hz` judge a missing topic once the graph around it has been heard."""

from types import SimpleNamespace

import pytest
from wirefish_operator.verb import topic as topic_verb
from wirefish_operator.verb.topic import _Probe, DISCOVERY_S, WAIT_S

TOPIC = '/ns/strem'
GRAPH = [('/ns/stream', ['std_msgs/msg/String']), ('/ns/state', ['std_msgs/msg/String'])]
WANTED = [('/ns/strem', ['std_msgs/msg/String'])]


class _Discovery:
    """A probe's view of a graph that appears (topics, publishers) at given times, fake-timed."""

    def __init__(self, appears: dict[float, list]) -> None:
        self.now = 0.0
        self.appears = appears

    def get_topic_names_and_types(self) -> list:
        return [pair for at, pairs in self.appears.items() if self.now >= at for pair in pairs]

    def count_publishers(self, topic: str) -> int:
        return int(topic in dict(self.get_topic_names_and_types()))

    def spin_once(self, timeout_sec: float) -> None:
        self.now += timeout_sec


def _find(monkeypatch, appears: dict[float, list]) -> tuple[tuple, list[float], float]:
    """Return what ``_Probe.find`` returned, when it said it waits, and when it returned."""
    discovery = _Discovery(appears)
    monkeypatch.setattr(topic_verb, 'time', SimpleNamespace(monotonic=lambda: discovery.now))
    probe = _Probe(SimpleNamespace(node=discovery, executor=discovery))
    waited: list[float] = []
    found = probe.find(TOPIC, lambda: waited.append(discovery.now))
    return found, waited, discovery.now


def test_a_graph_heard_at_once_without_the_topic_is_said_after_the_discovery_window(
        monkeypatch):
    (type_name, missing), waited, at = _find(monkeypatch, {0.0: GRAPH})
    assert type_name is None and 'did you mean /ns/stream' in missing
    assert waited == [] and at == pytest.approx(DISCOVERY_S, abs=0.15)


def test_a_graph_heard_late_is_judged_a_discovery_window_after_it_appeared(monkeypatch):
    (type_name, missing), waited, at = _find(monkeypatch, {4.0: GRAPH})
    assert type_name is None and 'did you mean /ns/stream' in missing
    assert waited == [pytest.approx(DISCOVERY_S, abs=0.15)]
    assert at == pytest.approx(4.0 + DISCOVERY_S, abs=0.15)


def test_a_topic_published_late_is_found(monkeypatch):
    (type_name, missing), waited, at = _find(monkeypatch, {5.0: WANTED})
    assert (type_name, missing) == ('std_msgs/msg/String', None)
    assert at == pytest.approx(5.0, abs=0.15)


def test_a_topic_published_before_its_graph_settled_is_not_called_missing(monkeypatch):
    (type_name, missing), _, _ = _find(monkeypatch, {4.0: GRAPH, 4.0 + DISCOVERY_S / 2: WANTED})
    assert (type_name, missing) == ('std_msgs/msg/String', None)


def test_no_graph_at_all_ends_the_wait_with_neither(monkeypatch):
    (type_name, missing), waited, at = _find(monkeypatch, {})
    assert (type_name, missing) == (None, None)
    assert len(waited) == 1 and at == pytest.approx(WAIT_S, abs=0.15)
