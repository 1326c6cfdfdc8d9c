# SPDX-License-Identifier: Apache-2.0
"""wirefish_msgs travel between processes over real DDS."""

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from ros_utils import PEERS, spin_until
from wirefish_msgs.msg import BodyWave
from wirefish_msgs.srv import RetuneGait

pytestmark = pytest.mark.ros


def test_body_wave_published_in_one_process_arrives_in_another(ros_context, spawn, python):
    talker = spawn([python, PEERS, 'body_wave_talker'])
    node = rclpy.create_node('listener', context=ros_context)
    received: list[BodyWave] = []
    node.create_subscription(BodyWave, 'body_wave', received.append, 10)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        assert spin_until(executor, lambda: len(received) >= 3, timeout_s=20.0), \
            'no BodyWave received; talker said: ' + (talker.stdout.read() if talker.poll() else '')
        msg = received[-1]
        assert msg.header.frame_id == 'tail_base'
        assert list(msg.q) == [0.0, 0.1, 0.2]
        assert msg.beta1 == 0.25
        assert msg.y[2] > 0.0  # the counter: a live stream, not one latched sample
    finally:
        executor.shutdown()
        node.destroy_node()


def test_retune_gait_service_called_across_processes(ros_context, spawn, python):
    spawn([python, PEERS, 'retune_server'])
    node = rclpy.create_node('retune_client', context=ros_context)
    client = node.create_client(RetuneGait, 'retune_gait')
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        assert spin_until(executor, client.service_is_ready, timeout_s=20.0)
        request = RetuneGait.Request()
        request.wave.c1, request.wave.c2 = 0.15, 1.0
        request.wave.k, request.wave.frequency_hz = 8.0, 1.0
        request.max_iterations = 7
        future = client.call_async(request)
        assert spin_until(executor, future.done, timeout_s=10.0)
        response = future.result()
        assert response.success
        assert response.params.frequency_hz == 1.0
        assert list(response.params.amplitude) == [0.15, 1.0]
        assert response.iterations == 7
    finally:
        executor.shutdown()
        node.destroy_node()
