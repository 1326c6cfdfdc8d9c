# SPDX-License-Identifier: Apache-2.0
"""
A second `wirefish up` in a namespace whose nodes already run refuses, unless told otherwise.

Two graphs in one namespace double every node (two CPGs interleaving commands to one fish):
`wirefish up` looks for the registry's nodes in its namespace first. A node of the registry
started by hand is enough to be found, so these tests need no whole first graph (the one in
test_whole_graph.py is also checked against a second start).
"""

import signal
import subprocess

from e2e_utils import lines_until_running
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until, stop_process
from wirefish_bringup.graph import fish_graph

pytestmark = pytest.mark.ros


@pytest.fixture
def occupied(spawn, ros_context, request) -> str:
    """Return a namespace in which the registry's cpg_node already runs (on this test's domain)."""
    namespace = '/e2e_dup_' + request.node.name.split('[')[0][-20:]
    spec = next(s for s in fish_graph(namespace, sim=True) if s.name == 'cpg_node')
    spawn([str(spec.executable_path()), *spec.command_arguments()])
    probe = rclpy.create_node('dup_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    try:
        assert spin_until(executor, lambda: ('cpg_node', namespace)
                          in probe.get_node_names_and_namespaces(), timeout_s=30.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
    return namespace


def test_up_in_a_namespace_in_use_refuses_with_one_line_and_starts_nothing(
        occupied, python, ros_env, tmp_path):
    result = subprocess.run([python, '-m', 'wirefish_cli.cli', 'up', '--sim', '--no-status',
                             '--namespace', occupied, '--out', str(tmp_path / 'out')],
                            env=ros_env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert f'namespace {occupied} is in use on ROS domain {ros_env["ROS_DOMAIN_ID"]}' in lines[0]
    assert 'cpg_node' in lines[0] and '--allow-duplicate' in lines[0]
    assert result.stdout == ''
    assert not (tmp_path / 'out').exists()  # nothing started, nothing written


def test_allow_duplicate_starts_the_graph_anyway(occupied, python, ros_env, spawn, tmp_path):
    launcher = spawn([python, '-m', 'wirefish_cli.cli', 'up', '--sim', '--no-status',
                      '--allow-duplicate', '--namespace', occupied, '--out', str(tmp_path)])
    seen = lines_until_running(launcher, 120.0)
    assert seen and seen[-1].startswith('running:'), ''.join(seen)
    launcher.send_signal(signal.SIGINT)
    assert stop_process(launcher, timeout_s=20.0) == 0
