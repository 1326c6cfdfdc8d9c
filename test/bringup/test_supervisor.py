"""The supervisor tracks and stops every process it starts, even several of the same name."""

import psutil
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until
from wirefish_bringup.graph import NodeSpec
from wirefish_bringup.supervisor import Supervisor

pytestmark = pytest.mark.ros


def test_same_named_processes_are_all_stopped_with_exit_code_0(tmp_path, ros_env, ros_context):
    supervisor = Supervisor(tmp_path, env=ros_env)
    procs = [supervisor.start(NodeSpec('wirefish_cpg', 'cpg_node', 'cpg_node',
                                       ('--ros-args', '-r', f'__ns:=/fish_{i}')))
             for i in (1, 2)]
    assert sorted(supervisor.processes) == ['cpg_node', 'cpg_node_2']
    assert all(psutil.pid_exists(p.pid) for p in procs)
    # Stop them once they are up (as the launcher does), not while they are still importing.
    node = rclpy.create_node('probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    up = {('cpg_node', '/fish_1'), ('cpg_node', '/fish_2')}
    try:
        assert spin_until(executor, lambda: up <= set(node.get_node_names_and_namespaces()),
                          timeout_s=30.0)
    finally:
        executor.shutdown()
        node.destroy_node()
    codes = supervisor.stop()
    assert codes == {'cpg_node_2': 0, 'cpg_node': 0}
    assert sorted(p.name for p in tmp_path.glob('*.log')) == ['cpg_node.log', 'cpg_node_2.log']
