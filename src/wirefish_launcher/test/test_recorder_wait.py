# SPDX-License-Identifier: Apache-2.0
"""A timed run on simulated time counts from when the recorder subscribes to the fish's clock."""

from dataclasses import dataclass

from wirefish_launcher.stop_flag import StopFlag
from wirefish_launcher.verb import up as launcher


@dataclass
class _Info:
    node_name: str


class _Graph:
    """A probe node whose graph shows the recorder's clock subscription from a given call on."""

    def __init__(self, recorder_from_call: int) -> None:
        self.calls = 0
        self._from = recorder_from_call

    def get_subscriptions_info_by_topic(self, topic: str) -> list[_Info]:
        self.calls += 1
        infos = [_Info('tf_node')]
        return infos + [_Info('wirefish_recorder')] if self.calls >= self._from else infos


def test_the_run_waits_until_the_recorder_takes_the_clock():
    graph = _Graph(recorder_from_call=3)
    assert launcher._recorder_takes(graph, '/fish/clock', StopFlag())
    assert graph.calls == 3


def test_a_recorder_that_never_subscribes_is_given_up_on(monkeypatch):
    monkeypatch.setattr(launcher, 'RECORDER_WAIT_S', 0.2)
    assert not launcher._recorder_takes(_Graph(recorder_from_call=10 ** 6), '/fish/clock',
                                        StopFlag())


def test_a_stop_ends_the_wait_at_once():
    stop = StopFlag()
    stop.request()
    graph = _Graph(recorder_from_call=10 ** 6)
    assert not launcher._recorder_takes(graph, '/fish/clock', stop)
    assert graph.calls == 0
