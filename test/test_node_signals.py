"""SIGINT and SIGTERM stop every node with exit code 0 and no trace, busy or idle."""

import os
import signal

from ament_index_python.packages import get_package_prefix
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until

pytestmark = pytest.mark.ros
NODES = [('wirefish_cpg', 'cpg_node'), ('wirefish_cpg', 'tuner_node'),
         ('wirefish_kinematics', 'kinematics_node')]


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize('package, name', NODES)
def test_a_signal_stops_the_node_cleanly(spawn, ros_context, package, name, signum):
    executable = os.path.join(get_package_prefix(package), 'lib', package, name)
    proc = spawn([executable, '--ros-args', '-p', 'publish_rate_hz:=1000.0']
                 if name == 'cpg_node' else [executable])  # a busy CPG: 1 kHz of callbacks
    probe = rclpy.create_node('signal_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    try:
        assert spin_until(executor, lambda: name in probe.get_node_names(), timeout_s=30.0)
    finally:
        executor.shutdown()
        probe.destroy_node()
    proc.send_signal(signum)
    code = proc.wait(timeout=20.0)
    output = proc.stdout.read()
    assert code == 0, output
    assert 'Traceback' not in output
