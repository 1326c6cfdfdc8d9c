# SPDX-License-Identifier: Apache-2.0
"""
kinematics_node on simulated time, in-process: it holds the virtual fish's clock at its ticks.

The test owns the clock: it publishes ``<namespace>/clock`` and servo_cmd by hand, steps the
clock only up to the tick the node last said is due (as fish_sim does), and reads the answers
on ``lockstep/next_tick`` and the body_wave they let through.
"""

from collections.abc import Iterator

from clock_owner import ClockOwner, on_simulated_time, stamp
import pytest
from ros_utils import spin_until

# In-process and brief, it mostly waits: no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

NAMESPACE = '/kinematics_hold'
STEP_NS = 10_000_000  # one servo_cmd per step, as the CPG's 100 Hz
TICK_NS = 20_000_000  # publish_rate_hz 50
ORIGIN_NS = 1_000 * 1_000_000_000


@pytest.fixture
def held(ros_context) -> Iterator:
    """Yield (executor, step(ns), answers, holders, body_wave stamps) on the test's clock."""
    from rclpy.qos import qos_profile_sensor_data, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState
    from wirefish_kinematics.kinematics_node import KinematicsNode
    from wirefish_msgs.msg import BodyWave

    node = KinematicsNode(context=ros_context, **on_simulated_time(NAMESPACE))
    owner = ClockOwner(ros_context, NAMESPACE, node)
    body: list[int] = []
    owner.node.create_subscription(
        BodyWave, 'body_wave',
        lambda m: body.append(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec),
        QoSProfile(depth=1000, reliability=ReliabilityPolicy.BEST_EFFORT))
    servo = owner.node.create_publisher(JointState, 'servo_cmd', qos_profile_sensor_data)

    def step(time_ns: int) -> None:
        """Publish the servo command of the step at ``time_ns``, then the clock there."""
        msg = JointState(name=['servo_1', 'servo_2'], position=[0.1, -0.1])
        msg.header.stamp = stamp(time_ns)
        servo.publish(msg)
        owner.set_clock(time_ns)

    try:
        yield owner.executor, step, owner.answers, owner.holders, body
    finally:
        owner.close()
        node.destroy_node()


def _first_answer(executor, step, answers) -> tuple[int, int]:
    """Step the clock until the node answers a tick; return (the clock, the tick next due)."""
    time_ns = ORIGIN_NS

    def answered() -> bool:
        nonlocal time_ns
        if answers:
            return True
        time_ns += STEP_NS
        step(time_ns)
        return False

    assert spin_until(executor, answered, 10.0), 'the kinematics never answered a tick'
    spin_until(executor, lambda: False, 0.2)  # every answer of the clock's last step
    return time_ns, answers[-1]


@pytest.mark.ros
def test_each_tick_says_under_its_name_the_next_is_due_a_publish_period_later(held):
    executor, step, answers, holders, _ = held
    _, due = _first_answer(executor, step, answers)
    for _ in range(3):
        step(due - STEP_NS)
        step(due)
        assert spin_until(executor, lambda: answers[-1] > due, 5.0)
        assert answers[-1] == due + TICK_NS
        due = answers[-1]
    assert holders == {f'{NAMESPACE}/kinematics_node'}


@pytest.mark.ros
def test_a_clock_that_waits_for_each_answer_gets_a_body_wave_every_other_step(held):
    executor, step, answers, _, body = held
    time_ns, due = _first_answer(executor, step, answers)
    first = due + STEP_NS  # every step's command from here on, as fast as the node answers
    while time_ns < first + 200 * STEP_NS:
        while time_ns + STEP_NS <= answers[-1]:  # up to the tick due, no further
            time_ns += STEP_NS
            step(time_ns)
        assert spin_until(executor, lambda: answers[-1] > time_ns, 5.0), \
            f'no answer of the tick at {time_ns}'
    spin_until(executor, lambda: False, 0.3)
    window = [t for t in body if first <= t < first + 200 * STEP_NS]
    assert len(window) == 100 and all(b - a == TICK_NS for a, b in zip(window, window[1:]))


@pytest.mark.ros
def test_off_simulated_time_it_says_nothing(ros_context):
    from wirefish_common.topics import LOCKSTEP_HOLD_TOPIC
    from wirefish_kinematics.kinematics_node import KinematicsNode

    node = KinematicsNode(context=ros_context, namespace=NAMESPACE)
    try:
        assert node.count_publishers(f'{NAMESPACE}/{LOCKSTEP_HOLD_TOPIC}') == 0
    finally:
        node.destroy_node()
