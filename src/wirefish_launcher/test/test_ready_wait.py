# SPDX-License-Identifier: Apache-2.0
"""`wirefish up` waiting for its nodes says how far start-up has got, then gives up in time."""

from dataclasses import dataclass, field

import pytest
from wirefish_launcher import monitor
from wirefish_launcher.stop_flag import StopFlag
from wirefish_launcher.verb import up as launcher


@dataclass
class _Spec:
    ros_nodes: tuple[str, ...]
    namespace: str | None = None


@dataclass
class _Supervisor:
    specs: dict = field(default_factory=lambda: {
        'cpg_node': _Spec(('cpg_node',)), 'planner_node': _Spec(('planner_node',))})
    given_up: set = field(default_factory=set)

    def supervise(self) -> list[str]:
        return []

    def down(self) -> list[str]:
        return []


class _Executor:
    def spin_once(self, timeout_sec: float) -> None:
        pass


@pytest.fixture
def slow_graph(monkeypatch):
    """Only cpg_node of /fish is ever discovered; progress lines every 0.05 s."""
    monkeypatch.setattr(monitor, 'discovered_nodes', lambda _node: {'/fish/cpg_node'})
    monkeypatch.setattr(launcher, 'READY_PROGRESS_S', 0.05)


def test_a_slow_start_says_what_it_waits_for_and_gives_up_at_the_deadline(slow_graph, capsys):
    status, live = launcher._wait_ready(None, _Executor(), '/fish', [], _Supervisor(), False,
                                        StopFlag(), timeout_s=0.3)
    assert (status, live) == ('not up after 0.3 s: /fish/planner_node', None)
    progress = [line for line in capsys.readouterr().err.splitlines() if 'nodes up after' in line]
    assert progress and all('1 of 2 nodes up' in line and 'waiting for /fish/planner_node'
                            in line for line in progress)


def test_a_stop_request_while_waiting_prints_no_progress(slow_graph, capsys):
    stop = StopFlag()
    stop.request()
    status, _ = launcher._wait_ready(None, _Executor(), '/fish', [], _Supervisor(), False, stop,
                                     timeout_s=0.2)
    assert status is None
    assert 'nodes up after' not in capsys.readouterr().err
