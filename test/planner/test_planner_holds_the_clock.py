# SPDX-License-Identifier: Apache-2.0
"""
planner_node on simulated time, in-process: it holds the virtual fish's clock at its ticks.

The test is the clock's owner here: it publishes ``<namespace>/clock`` and imu/data by hand and
reads what the planner answers on ``lockstep/next_tick`` (what fish_sim waits for).
"""

from collections.abc import Iterator

from clock_owner import ClockOwner, on_simulated_time, stamp
import pytest
from ros_utils import spin_until

NAMESPACE = '/planner_hold'
TICK_NS = 50_000_000  # control_rate_hz 20
ORIGIN_NS = 1_000 * 1_000_000_000


@pytest.fixture
def held(ros_context) -> Iterator:
    """Yield (executor, set_clock(ns), send_imu(ns), answers, holders) on the test's clock."""
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu
    from wirefish_planner.planner_node import PlannerNode

    planner = PlannerNode(context=ros_context, **on_simulated_time(NAMESPACE))
    owner = ClockOwner(ros_context, NAMESPACE, planner)
    imu = owner.node.create_publisher(Imu, 'imu/data', qos_profile_sensor_data)

    def send_imu(time_ns: int) -> None:
        msg = Imu()
        msg.header.stamp = stamp(time_ns)
        msg.orientation.w = 1.0
        imu.publish(msg)

    try:
        yield owner.executor, owner.set_clock, send_imu, owner.answers, owner.holders
    finally:
        owner.close()
        planner.destroy_node()


def _first_answer(executor, set_clock, send_imu, answers) -> int:
    """Step the clock (with imu/data) until the planner answers a tick; return its next tick."""
    time_ns = ORIGIN_NS

    def answered() -> bool:
        nonlocal time_ns
        if answers:
            return True
        time_ns += 10_000_000
        send_imu(time_ns)
        set_clock(time_ns)
        return False

    assert spin_until(executor, answered, 10.0), 'the planner never answered a tick'
    spin_until(executor, lambda: False, 0.2)  # every answer of the clock's last step
    return answers[-1]


@pytest.mark.ros
def test_each_tick_says_the_next_one_is_due_a_control_period_later(held):
    executor, set_clock, send_imu, answers, holders = held
    due = _first_answer(executor, set_clock, send_imu, answers)
    for _ in range(3):
        send_imu(due)
        set_clock(due)
        assert spin_until(executor, lambda: answers[-1] > due, 5.0)
        assert answers[-1] == due + TICK_NS
        due = answers[-1]
    assert holders == {f'{NAMESPACE}/planner_node'}  # its name: the clock keeps a hold per node


@pytest.mark.ros
def test_a_tick_whose_imu_lags_the_clock_waits_for_the_sample(held):
    executor, set_clock, send_imu, answers, _ = held
    due = _first_answer(executor, set_clock, send_imu, answers)
    set_clock(due)  # the tick comes, its newest sample 50 ms old
    spin_until(executor, lambda: False, 0.3)
    assert answers[-1] == due, 'answered without the sample of its tick'
    send_imu(due)
    assert spin_until(executor, lambda: answers[-1] == due + TICK_NS, 5.0)


@pytest.mark.ros
def test_imu_silent_past_the_wait_stops_holding_the_ticks_until_a_sample_comes(held):
    from wirefish_planner.planner_node import INPUT_WAIT_S

    executor, set_clock, send_imu, answers, _ = held
    due = _first_answer(executor, set_clock, send_imu, answers)
    set_clock(due)
    assert spin_until(executor, lambda: answers[-1] == due + TICK_NS, INPUT_WAIT_S + 5.0)
    due = answers[-1]
    set_clock(due)  # still no sample: this tick does not wait
    assert spin_until(executor, lambda: answers[-1] == due + TICK_NS, 0.5)
    due = answers[-1]
    send_imu(due - TICK_NS)  # one came, older than the next tick: that tick waits again
    spin_until(executor, lambda: False, 0.2)
    set_clock(due)
    spin_until(executor, lambda: False, 0.3)
    assert answers[-1] == due
