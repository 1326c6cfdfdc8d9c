# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the view tests: one `wirefish up --sim --view` per module, on free ports."""

from collections.abc import Iterator
from dataclasses import dataclass
import os
from pathlib import Path
import socket
import time

from e2e_utils import RunningGraph, start_graph, stopped_on_exit
from foxglove_client import free_port
from headless_chromium import headless_chromium
import pytest
from ros_utils import domain_context
from wirefish_bringup.graph import default_params_file
import yaml


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
    """
    Start `wirefish up --sim --view` with the view on free ports; stop it afterwards.

    A module may set ``GRAPH_OPTIONS`` (more `wirefish up` options) and ``GRAPH_PARAMS``
    ({node: {parameter: value}}, over the default parameter file's).
    """
    domain = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19
    out = tmp_path_factory.mktemp('view_run')
    ws_port, http_port = free_port(), free_port()
    params = Path(out, 'params.yaml')
    document = yaml.safe_load(default_params_file().read_text())
    wanted = {'view_node': {'port': ws_port, 'http_port': http_port},
              **getattr(request.module, 'GRAPH_PARAMS', {})}
    for node, values in wanted.items():
        document.setdefault(f'/**/{node}', {}).setdefault('ros__parameters', {}).update(values)
    params.write_text(yaml.safe_dump(document))
    namespace = '/e2e_' + request.module.__name__.rsplit('.', 1)[-1]
    graph = start_graph(domain, out, '--view', '--params-file', str(params),
                        *getattr(request.module, 'GRAPH_OPTIONS', ()), namespace=namespace)
    with stopped_on_exit(graph):
        assert _wait_listening(ws_port, 30.0), 'the view does not listen'
        yield ViewGraph(graph, ws_port, http_port)


@pytest.fixture
def graph_context(view_graph: ViewGraph):
    """Yield an rclpy context of this test's own, on the view graph's domain."""
    with domain_context(view_graph.graph.domain_id) as context:
        yield context


class DashboardPage:
    """The dashboard in headless chromium (Debian's) driven by Selenium, and its live values."""

    def __init__(self, driver) -> None:
        """Wrap a Selenium ``driver`` on the page."""
        self.driver = driver

    def live(self, expression: str):
        """Return the value of a JavaScript expression on the page."""
        return self.driver.execute_script(f'return {expression};')

    def wait(self, expression: str, timeout_s: float) -> bool:
        """Return True once ``expression`` is true on the page, False after ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.live(expression):
                return True
            time.sleep(0.1)
        return bool(self.live(expression))

    def text(self, element_id: str) -> str:
        """Return the visible text of the element ``element_id``."""
        from selenium.webdriver.common.by import By
        return self.driver.find_element(By.ID, element_id).text


@pytest.fixture(scope='module')
def dashboard(view_graph: ViewGraph,
              tmp_path_factory: pytest.TempPathFactory) -> Iterator[DashboardPage]:
    """Yield the module's graph's dashboard in a headless chromium (1400 x 1300); quit it after."""
    with headless_chromium(view_graph.http_url, tmp_path_factory.mktemp('chromium')) as driver:
        yield DashboardPage(driver)
