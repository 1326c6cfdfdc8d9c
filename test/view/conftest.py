"""Fixtures of the view tests: one `wirefish up --sim --view` per module, on free ports."""

from collections.abc import Iterator
from dataclasses import dataclass
import os
from pathlib import Path
import socket
import time

from e2e_utils import descendants, RunningGraph, start_graph
from foxglove_client import free_port
import pytest
from ros_utils import stop_process
from wirefish_bringup.graph import default_params_file


@dataclass
class ViewGraph:
    """A running graph with its view: the graph and the view's two ports."""

    graph: RunningGraph
    ws_port: int
    http_port: int

    @property
    def ws_url(self) -> str:
        return f'ws://127.0.0.1:{self.ws_port}'

    @property
    def http_url(self) -> str:
        return f'http://127.0.0.1:{self.http_port}/'


def _wait_listening(port: int, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with socket.socket() as probe:
            if probe.connect_ex(('127.0.0.1', port)) == 0:
                return True
        time.sleep(0.2)
    return False


@pytest.fixture(scope='module')
def view_graph(tmp_path_factory, request) -> Iterator[ViewGraph]:
    """Start `wirefish up --sim --view` with the view on free ports; stop it afterwards."""
    domain = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19
    out = tmp_path_factory.mktemp('view_run')
    ws_port, http_port = free_port(), free_port()
    params = Path(out, 'params.yaml')
    params.write_text(default_params_file().read_text() + (
        f'\n/**/view_node:\n  ros__parameters:\n    port: {ws_port}\n'
        f'    http_port: {http_port}\n'))
    namespace = '/e2e_' + request.module.__name__.rsplit('.', 1)[-1]
    graph = start_graph(domain, out, '--view', '--params-file', str(params),
                        namespace=namespace)
    children = descendants(graph.launcher.pid)
    try:
        assert _wait_listening(ws_port, 30.0), 'the view does not listen'
        yield ViewGraph(graph, ws_port, http_port)
    finally:
        stop_process(graph.launcher, timeout_s=10.0)
        for child in children:
            if child.is_running():
                child.kill()
        graph.launcher.stdout.close()


@pytest.fixture
def graph_context(view_graph: ViewGraph, monkeypatch: pytest.MonkeyPatch):
    """Yield an rclpy context of this test's own, on the view graph's domain."""
    import rclpy
    from rclpy.context import Context

    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    context = Context()
    rclpy.init(context=context, domain_id=view_graph.graph.domain_id)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)
