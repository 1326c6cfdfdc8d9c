# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the whole graph's tests: one graph shared by a module's tests, the cpg probe."""

from collections.abc import Iterator
import os

from cpg_fixtures import probe  # noqa: F401 (a fixture, found by name)
from e2e_utils import RunningGraph, start_graph, stopped_on_exit
import pytest
from ros_utils import domain_context


@pytest.fixture(scope='module')
def e2e_domain_id() -> int:
    """Return the ROS domain of this module's graph (outside the per-test window)."""
    return int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19


@pytest.fixture(scope='module')
def running_graph(e2e_domain_id: int, tmp_path_factory, request) -> Iterator[RunningGraph]:
    """Yield one whole graph shared by the module's observation tests; stop it afterwards."""
    namespace = '/e2e_' + request.module.__name__.rsplit('.', 1)[-1]  # one per module
    graph = start_graph(e2e_domain_id, tmp_path_factory.mktemp('e2e_run'), namespace=namespace)
    with stopped_on_exit(graph):
        yield graph


@pytest.fixture
def graph_context(running_graph: RunningGraph):
    """Yield an rclpy context of this test's own, on the shared graph's domain."""
    with domain_context(running_graph.domain_id) as context:
        yield context
