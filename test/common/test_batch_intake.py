# SPDX-License-Identifier: Apache-2.0
"""BatchIntake: the messages of a topic wait in its queue until taken, whatever the executor."""

import time

import pytest
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from wirefish_common.batch_intake import BatchIntake
from wirefish_common.cdr_views import read_joint_state
from wirefish_common.executors import make_executor

pytestmark = pytest.mark.ros
QOS = QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE)


def test_every_message_is_taken_in_order_on_the_nodes_resolved_topic(ros_context):
    import rclpy

    node = rclpy.create_node('consumer', namespace='/intake_test', context=ros_context)
    talker = rclpy.create_node('talker', context=ros_context)
    executor = make_executor('events', context=ros_context)
    executor.add_node(node)
    intake = BatchIntake(node, JointState, 'servo_cmd', QOS)
    publisher = talker.create_publisher(JointState, '/intake_test/servo_cmd', QOS)
    try:
        assert intake.topic == '/intake_test/servo_cmd'
        deadline = time.monotonic() + 10.0
        while publisher.get_subscription_count() == 0:
            assert time.monotonic() < deadline, 'the intake never matched'
            time.sleep(0.05)
        for i in range(20):
            publisher.publish(JointState(name=['servo_1'], position=[float(i)]))
            executor.spin_once(timeout_sec=0.001)  # the executor never takes them
        taken: list = []
        deadline = time.monotonic() + 10.0
        while len(taken) < 20 and time.monotonic() < deadline:
            taken += [read_joint_state(data).position[0] for data in intake.take()]
            time.sleep(0.01)
        assert taken == [float(i) for i in range(20)]
        assert intake.take() == []
    finally:
        intake.destroy()
        executor.remove_node(node)
        executor.shutdown()
        talker.destroy_node()
        node.destroy_node()
