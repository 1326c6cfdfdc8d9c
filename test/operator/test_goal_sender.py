# SPDX-License-Identifier: Apache-2.0
"""
GoalSender against a real tuner: a goal whose answer is lost is adopted from the status.

rmw_fastrtps can drop the answer to a goal (see wirefish_operator.goal_sender). The test loses
it on purpose: the goal goes to the tuner, but the client is handed a future that is never
answered. The sender must find the goal in the tuner's status array, adopt it without sending
it again, and get its result.
"""

import time

from action_msgs.msg import GoalStatus
import pytest
from rclpy.action import ActionClient
from rclpy.task import Future
from ros_utils import spin_until
from wirefish_msgs.action import RetuneGait as RetuneGaitAction
from wirefish_msgs.msg import BodyWaveSpec
from wirefish_operator.goal_sender import GoalSender

pytestmark = pytest.mark.ros
WAIT_S = 30.0


def goal(**fields) -> RetuneGaitAction.Goal:
    message = RetuneGaitAction.Goal(**fields)
    message.wave = BodyWaveSpec(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0)
    return message


def _sender(probe, client) -> GoalSender:
    return GoalSender(probe.node, client, lambda s: probe.executor.spin_once(timeout_sec=s),
                      'retune_gait', RetuneGaitAction)


def test_a_goal_whose_answer_is_lost_is_adopted_and_its_result_arrives(tuner, probe):
    tuner()
    client = ActionClient(probe.node, RetuneGaitAction, 'retune_gait')
    assert spin_until(probe.executor, client.server_is_ready, WAIT_S), 'no action server'
    real_send, sent_ids = client.send_goal_async, []

    def send_and_lose_the_answer(message, feedback_callback=None, goal_uuid=None):
        sent_ids.append(bytes(goal_uuid.uuid))
        real_send(message, feedback_callback=feedback_callback, goal_uuid=goal_uuid)
        return Future()  # the answer never reaches us

    client.send_goal_async = send_and_lose_the_answer
    sender = _sender(probe, client)
    handle = sender.send(goal(seed=2, max_iterations=40, swarm_size=20, use_library=False),
                         lambda _feedback: None, time.monotonic() + WAIT_S)
    assert handle is not None and handle.accepted
    assert sender.resent == 0 and bytes(handle.goal_id.uuid) == sent_ids[0]
    result = handle.get_result_async()
    assert spin_until(probe.executor, result.done, WAIT_S), 'no result for the adopted goal'
    assert result.result().status == GoalStatus.STATUS_SUCCEEDED
    assert result.result().result.iterations > 0


def test_a_goal_answered_as_usual_is_sent_once(tuner, probe):
    tuner()
    client = ActionClient(probe.node, RetuneGaitAction, 'retune_gait')
    assert spin_until(probe.executor, client.server_is_ready, WAIT_S), 'no action server'
    sender = _sender(probe, client)
    handle = sender.send(goal(seed=2, max_iterations=10, swarm_size=20, use_library=False),
                         lambda _feedback: None, time.monotonic() + WAIT_S)
    assert handle is not None and handle.accepted and sender.resent == 0
