# SPDX-License-Identifier: Apache-2.0
"""
A node removed from a busy events executor leaves the graph once ``settle`` has run.

``run_node``'s stop removes the node, lets the executor let go of it, destroys it and exits:
a node the executor still holds is not destroyed, and stays in every other participant's graph
until the lease of its participant (~20 s) runs out. Here the node's executor has callbacks
waiting when the node is removed, as a busy node's has when a signal stops it. Then the
participant outlives the node it leaves with (``graph_exit``).
"""

import threading

import pytest
import rclpy
from ros_utils import domain_context, probe_node, spin_until
from wirefish_common.executors import make_executor, settle
from wirefish_common.graph_exit import destroy_leaving_the_graph, holder_name

pytestmark = pytest.mark.ros

LISTED_S = 10.0  # discovery of a new node on a loaded machine
GONE_S = 3.0     # a destroyed node's goodbye is one message on the host
LINGER_S = 2.0   # long enough for the probe to see the node gone before its participant


def _listed(probe, name: str) -> bool:
    return name in [n for n, _ in probe.get_node_names_and_namespaces()]


@pytest.mark.parametrize('kind', ['events', 'classic'])
def test_a_busy_node_removed_and_settled_leaves_the_graph_when_destroyed(
        ros_context, ros_domain_id, kind):
    name = f'busy_{kind}'
    with probe_node('leave_probe', ros_context) as (probe, probe_executor), \
            domain_context(ros_domain_id) as context:
        node = rclpy.create_node(name, context=context)
        node.create_timer(0.001, lambda: None)
        executor = make_executor(kind, context)
        executor.add_node(node)
        try:
            assert spin_until(executor, lambda: _listed(probe, name), LISTED_S)
            for _ in range(50):  # the node at work: its entities taken, its timer firing
                executor.spin_once(timeout_sec=0.01)
            for _ in range(3):  # callbacks waiting when the stop comes
                executor.create_task(lambda: None)
            executor.remove_node(node)
            assert settle(executor)
            node.destroy_node()
            assert spin_until(probe_executor, lambda: not _listed(probe, name), GONE_S)
        finally:
            executor.shutdown()


def test_a_node_leaving_the_graph_goes_before_its_participant(ros_context, ros_domain_id):
    name = 'leaving'
    with probe_node('leave_probe', ros_context) as (probe, probe_executor), \
            domain_context(ros_domain_id) as context:
        node = rclpy.create_node(name, context=context)
        assert spin_until(probe_executor, lambda: _listed(probe, name), LISTED_S)
        leaving = threading.Thread(target=destroy_leaving_the_graph, args=(node, LINGER_S))
        leaving.start()
        try:
            # The node's own update reaches the probe while its participant still holds on.
            assert spin_until(probe_executor, lambda: not _listed(probe, name)
                              and _listed(probe, holder_name(name)), LINGER_S + GONE_S)
        finally:
            leaving.join()
        assert spin_until(probe_executor, lambda: not _listed(probe, holder_name(name)), GONE_S)
        assert not _listed(probe, name)
