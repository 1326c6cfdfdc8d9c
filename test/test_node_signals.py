"""SIGINT and SIGTERM stop every node of the registry with exit code 0 and no trace."""

import signal

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from wirefish_bringup.graph import composable_entries, fish_graph

pytestmark = pytest.mark.ros
# Every ROS node of the registry (those with a node class), as the launcher starts it: its name,
# namespace, the default parameter file and its extra parameters. The bridge's device does not
# exist: the bridge keeps retrying it, which is the state a real fish's bridge waits in.
NAMESPACE = '/h_signals'
DEVICE = '/tmp/wirefish-h-signals-no-such-device'
NODES = [spec for spec in fish_graph(NAMESPACE, sim=False, port=DEVICE)
         if spec.name in {e.name for e in composable_entries()}]
# Extra load for a node whose rate is a parameter: a busy CPG is 1 kHz of callbacks.
BUSY = {'cpg_node': ('-p', 'publish_rate_hz:=1000.0')}


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize('spec', NODES, ids=[spec.name for spec in NODES])
def test_a_signal_stops_the_node_cleanly(spawn, ros_context, spec, signum):
    proc = spawn([str(spec.executable_path()), *spec.command_arguments(),
                  *BUSY.get(spec.name, ())])
    probe = rclpy.create_node('signal_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    try:
        assert spin_until(executor, lambda: (spec.name, NAMESPACE)
                          in probe.get_node_names_and_namespaces(), timeout_s=30.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
    proc.send_signal(signum)
    code = proc.wait(timeout=20.0)
    output = proc.stdout.read()
    assert code == 0, output
    assert 'Traceback' not in output
