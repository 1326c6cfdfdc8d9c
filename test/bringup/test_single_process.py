# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --single-process`: a retune with apply reaches the CPG in the same process."""

import re
import signal
import subprocess
import sys

from e2e_utils import start_graph
import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from ros_utils import spin_until
from sensor_msgs.msg import JointState

pytestmark = pytest.mark.ros

# A wave unlike the default gait's (1 Hz), so the CPG's beat shows whether the fit was applied.
WAVE = ('--c1', '0.10', '--c2', '0.8', '--k', '6.0', '--freq', '1.5')
SETTLE_S = 1.5  # the CPG's amplitude and offset converge after a new parameter set
TRACE_S = 4.0  # six beats at 1.5 Hz


def _beat_hz(trace: np.ndarray) -> float:
    """Return the beat frequency of servo 1 from its upward mean crossings (whole periods)."""
    theta = trace[:, 1] - trace[:, 1].mean()
    up = np.flatnonzero((theta[:-1] < 0) & (theta[1:] >= 0))
    return (len(up) - 1) / (trace[up[-1], 0] - trace[up[0], 0])


def _retune_between_traces(context, graph) -> tuple[float, subprocess.CompletedProcess, float]:
    """Return servo_cmd's beat before, the answer of `wirefish retune --apply`, the beat after."""
    node = rclpy.create_node('e2e_single_probe', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    samples: list[tuple[float, float]] = []  # header stamp (s), theta1 (rad)

    def on_servo(msg: JointState) -> None:
        samples.append((msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec,
                        msg.position[0]))

    def trace_from(start: int) -> np.ndarray:
        """Spin for SETTLE_S + TRACE_S; return the samples of the last TRACE_S."""
        assert spin_until(executor, lambda: len(samples) > start
                          and samples[-1][0] > samples[start][0] + SETTLE_S + TRACE_S,
                          timeout_s=30.0), 'servo_cmd stopped'
        trace = np.array(samples[start:])
        return trace[trace[:, 0] >= trace[-1, 0] - TRACE_S]

    try:
        node.create_subscription(JointState, f'{graph.namespace}/servo_cmd', on_servo,
                                 qos_profile_sensor_data)
        before_hz = _beat_hz(trace_from(0))
        result = subprocess.run(
            [sys.executable, '-m', 'wirefish_cli.cli', 'retune', '--namespace',
             graph.namespace, '--apply', '--iterations', '30', '--timeout', '60', *WAVE],
            env=graph.env, capture_output=True, text=True, timeout=120)
        return before_hz, result, _beat_hz(trace_from(len(samples)))
    finally:
        executor.shutdown()
        node.destroy_node()


def test_after_retune_with_apply_the_servos_beat_at_the_fitted_frequency_in_one_process(
        e2e_domain_id, tmp_path, monkeypatch):
    # A gait library of this test's own: a wave fitted by an earlier run is not fitted again.
    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    graph = start_graph(e2e_domain_id, tmp_path, '--single-process',
                        namespace='/e2e_single_process')
    try:
        monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        context = rclpy.context.Context()
        rclpy.init(context=context, domain_id=e2e_domain_id)
        try:
            before_hz, result, after_hz = _retune_between_traces(context, graph)
        finally:
            rclpy.try_shutdown(context=context)
    finally:
        graph.launcher.send_signal(signal.SIGINT)
        code = graph.launcher.wait(timeout=20.0)
        output = graph.launcher.stdout.read()
        graph.launcher.stdout.close()
    assert result.returncode == 0, result.stderr
    fitted_hz = float(re.search(r'^frequency_hz\s+(\S+)$', result.stdout, re.M).group(1))
    assert abs(fitted_hz - before_hz) > 0.25, (fitted_hz, before_hz)  # a change to be seen
    assert after_hz == pytest.approx(fitted_hz, rel=0.05), (before_hz, after_hz, result.stdout)
    assert code == 0, output
    for log in tmp_path.glob('run_*/logs/*.log'):
        assert 'Traceback' not in log.read_text(), log.name
