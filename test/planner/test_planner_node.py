# SPDX-License-Identifier: Apache-2.0
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
    # A refused command is no first command: the fish stays still.
    assert states and all(s.mode == 'still' and s.target_speed == 0.0 for s in states)


def _imu(node, stamp_s: float, yaw_rate: float):
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.stamp = node.get_clock().now().to_msg()
    msg.header.stamp.sec, msg.header.stamp.nanosec = int(stamp_s), int(stamp_s % 1.0 * 1e9)
    msg.orientation.w = 1.0
    msg.angular_velocity.z = yaw_rate
    return msg


@pytest.mark.ros
def test_imu_samples_taken_at_the_control_tick_close_the_yaw_loop(planner):
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu

    node, executor, states, publisher = planner
    imu = node.create_publisher(Imu, 'imu/data', qos_profile_sensor_data)
    cmd = Twist()
    cmd.linear.x, cmd.angular.z = 0.2, 0.1
    start, sent = time.monotonic(), [0]

    def measured() -> bool:
        # 100 Hz of samples turning at 0.05 rad/s, stamped on a clock of their own
        while sent[0] < (time.monotonic() - start) * 100.0:
            imu.publish(_imu(node, 1000.0 + sent[0] * 0.01, 0.05))
            sent[0] += 1
        publisher.publish(cmd)
        return any(s.mode != 'open_loop' and s.yaw_rate_measured == pytest.approx(0.05)
                   for s in states if s.target_speed == pytest.approx(0.2))

    assert spin_until(executor, measured, 10.0), [s.mode for s in states][-5:]


@pytest.mark.ros
def test_bytes_that_are_no_imu_are_skipped_and_the_next_samples_are_read(planner):
    from rclpy.qos import qos_profile_sensor_data
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import Imu

    node, executor, states, publisher = planner
    peer_imu = node.create_publisher(Imu, 'imu/data', qos_profile_sensor_data)
    heard_raw: list[bytes] = []
    node.create_subscription(Imu, 'imu/data', heard_raw.append, qos_profile_sensor_data,
                             raw=True)
    # the planner's intake and this test's own raw reader
    assert spin_until(executor, lambda: peer_imu.get_subscription_count() >= 2, 10.0)
    good = serialize_message(_imu(node, 5.0, 0.03))
    # A truncated sample, as a foreign writer's broken bytes would arrive: the reader refuses
    # it (CdrError), the node says so and goes on with the samples after it.
    peer_imu.publish(good[:40])
    assert spin_until(executor, lambda: len(heard_raw) == 1, 10.0)
    assert heard_raw[0] == good[:40]  # DDS carried the broken bytes as they were
    cmd = Twist()
    cmd.linear.x = 0.2
    start, sent = time.monotonic(), [0]

    def heard_after_the_bad_one() -> bool:
        # 100 Hz, the board's rate: the intake's queue holds two ticks of it, the bad one too
        while sent[0] < (time.monotonic() - start) * 100.0:
            sent[0] += 1
            peer_imu.publish(_imu(node, 5.0 + sent[0] * 0.01, 0.03))
        publisher.publish(cmd)
        return any(s.yaw_rate_measured == pytest.approx(0.03) for s in states)

    assert spin_until(executor, heard_after_the_bad_one, 10.0)
