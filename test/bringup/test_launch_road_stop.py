# SPDX-License-Identifier: Apache-2.0
"""
Stopping nodes started as `ros2 launch` starts them: soon after start-up, and out of the graph.

The claims: a SIGINT that reaches a node while it is still starting (stop signals held by the
launch file's prefix) ends it with exit code 0 before `ros2 launch` would escalate to SIGTERM
(its ``sigterm_timeout``, 5 s), however long its imports take, since nothing of the node exists
yet; a node stopped cleanly on the default (events) executor leaves every other participant's
graph within 2 s of its exit, instead of the ~20 s of its participant's lease.
"""

import os
import shlex
import signal
import subprocess
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import spin_until, stop_signals_blocked_soon
from wirefish_bringup.graph import composable_entries, fish_graph
from wirefish_common.startup_signals import held_start_prefix

pytestmark = pytest.mark.ros

NAMESPACE = '/launch_road_stop'
DEVICE = '/tmp/wirefish-launch-road-stop-no-such-device'
NODES = [spec for spec in fish_graph(NAMESPACE, sim=False, port=DEVICE)
         if spec.name in {e.name for e in composable_entries()}]
SIGTERM_TIMEOUT_S = 5.0  # launch's ExecuteProcess default: SIGTERM after that
LEFT_GRAPH_S = 2.0


def test_a_stop_soon_after_start_ends_each_node_before_launch_escalates(ros_env, tmp_path):
    prefix = shlex.split(held_start_prefix())
    took, codes, logs = {}, {}, {}
    for spec in NODES:
        log = tmp_path / f'{spec.name}.log'
        with open(log, 'w') as out:
            proc = subprocess.Popen([*prefix, str(spec.executable_path()),
                                     *spec.command_arguments()], env=ros_env,
                                    stdin=subprocess.DEVNULL, stdout=out,
                                    stderr=subprocess.STDOUT, start_new_session=True)
        try:
            assert stop_signals_blocked_soon(proc.pid), spec.name
            os.killpg(proc.pid, signal.SIGINT)
            sent = time.monotonic()
            codes[spec.name] = proc.wait(timeout=30.0)
            took[spec.name] = time.monotonic() - sent
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        logs[spec.name] = log.read_text()
    print('stop soon after start (s): '
          + ', '.join(f'{name} {seconds:.2f}' for name, seconds in took.items()))
    assert codes == dict.fromkeys(codes, 0), {n: logs[n][-800:] for n, c in codes.items() if c}
    assert {n: t for n, t in took.items() if t >= SIGTERM_TIMEOUT_S} == {}
    assert [n for n, text in logs.items() if 'Traceback' in text] == []


@pytest.mark.parametrize('name', ['cpg_node', 'tf_node'])
def test_a_node_stopped_cleanly_leaves_the_graph_at_once(spawn, ros_context, ros_env, name):
    assert ros_env.get('WIREFISH_EXECUTOR', 'events') in ('', 'events')  # the default
    spec = next(spec for spec in NODES if spec.name == name)
    proc = spawn([str(spec.executable_path()), *spec.command_arguments()])
    probe = rclpy.create_node('graph_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)

    def listed() -> bool:
        return (name, NAMESPACE) in probe.get_node_names_and_namespaces()

    try:
        assert spin_until(executor, listed, timeout_s=30.0)
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=20.0) == 0, proc.stdout.read()
        exited = time.monotonic()
        spin_until(executor, lambda: not listed(), timeout_s=25.0)
        gone_after = time.monotonic() - exited
    finally:
        executor.shutdown()
        probe.destroy_node()
    print(f'{name} left the graph {gone_after:.2f} s after its exit')
    assert gone_after <= LEFT_GRAPH_S
