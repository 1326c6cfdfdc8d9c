"""planner_node in-process: parameter updates are judged whole, cmd_vel is judged, state flows."""

import time

from geometry_msgs.msg import Twist
import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from ros_utils import spin_until


@pytest.fixture
def planner(ros_context):
    """Yield a planner_node of this test's own (no CPG: it has nobody to drive) and a peer."""
    import rclpy
    from wirefish_msgs.msg import PlannerState
    from wirefish_planner.planner_node import PlannerNode

    node = PlannerNode(context=ros_context, namespace='/h181_unit')
    peer = rclpy.create_node('peer', namespace='/h181_unit', context=ros_context)
    states = []
    peer.create_subscription(PlannerState, 'planner_state', states.append, 10)
    publisher = peer.create_publisher(Twist, 'cmd_vel', 10)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    executor.add_node(peer)
    try:
        yield node, executor, states, publisher
    finally:
        executor.shutdown()
        peer.destroy_node()
        node.destroy_node()


@pytest.mark.ros
@pytest.mark.parametrize('updates, words', [
    ({'min_frequency_hz': 5.0}, 'max_frequency_hz'),
    ({'max_offset_rad': 1.2, 'servo_limit_rad': 1.0}, 'leaves no servo range'),
    ({'turn_gain': 0.0}, 'turn_gain'),
    ({'cmd_vel_timeout_s': -1.0}, 'cmd_vel_timeout_s'),
])
def test_an_inconsistent_parameter_set_is_refused_and_changes_nothing(planner, updates, words):
    node, _, _, _ = planner
    before = {name: node.get_parameter(name).value for name in updates}
    result = node.set_parameters_atomically(
        [Parameter(name, value=value) for name, value in updates.items()])
    assert not result.successful and words in result.reason
    assert {name: node.get_parameter(name).value for name in updates} == before


@pytest.mark.ros
def test_cmd_vel_is_planned_and_stated(planner):
    node, executor, states, publisher = planner
    msg = Twist()
    msg.linear.x, msg.angular.z = 0.2, 0.1

    def heard_swimming() -> bool:
        publisher.publish(msg)
        return any(s.target_speed == pytest.approx(0.2) for s in states)

    assert spin_until(executor, heard_swimming, 10.0)
    state = [s for s in states if s.target_speed == pytest.approx(0.2)][-1]
    assert state.predicted_speed == pytest.approx(0.2, rel=1e-3)
    assert state.tail_beat_hz == pytest.approx(1.54, abs=0.01) and state.gait_family == 'table1'
    assert state.mode == 'open_loop'  # no imu/data here: feed-forward only
    assert state.yaw_rate_target == pytest.approx(0.1)


@pytest.mark.ros
def test_a_negative_speed_is_refused(planner):
    node, executor, states, publisher = planner
    msg = Twist()
    msg.linear.x = -0.2
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline:
        publisher.publish(msg)
        executor.spin_once(timeout_sec=0.05)
    assert states and all(s.mode == 'rest' and s.target_speed == 0.0 for s in states)
