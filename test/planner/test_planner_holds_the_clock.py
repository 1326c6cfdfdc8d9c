# SPDX-License-Identifier: Apache-2.0
"""
planner_node on simulated time, in-process: it holds the virtual fish's clock at its ticks.

The test is the clock's owner here: it publishes ``<namespace>/clock``, imu/data and cmd_vel by
hand, reads what the planner answers on ``lockstep/next_tick`` (what fish_sim waits for), and
plays the CPG's start service where a test needs one.
"""

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from clock_owner import ClockOwner, on_simulated_time, stamp
import pytest
from ros_utils import spin_until

NAMESPACE = '/planner_hold'
TICK_NS = 50_000_000  # control_rate_hz 20
ORIGIN_NS = 1_000 * 1_000_000_000


@dataclass
class Held:
    """The planner on the test's clock, and what the test does and hears around it."""

    owner: ClockOwner
    send_imu: Any
    send_cmd_vel: Any
    start_calls: list[int] = field(default_factory=list)  # answers said when each start came

    @property
    def executor(self) -> Any:
        return self.owner.executor

    @property
    def answers(self) -> list[int]:
        return self.owner.answers

    def set_clock(self, time_ns: int) -> None:
        self.owner.set_clock(time_ns)

    def serve_start(self) -> None:
        """Offer the CPG's start service (std_srvs/Trigger ``start``), recording each call."""
        from std_srvs.srv import Trigger

        def on_start(_request, response):
            self.start_calls.append(len(self.answers))
            response.success = True
            return response

        self.owner.node.create_service(Trigger, 'start', on_start)


@pytest.fixture
def held(ros_context) -> Iterator[Held]:
    """Yield the planner on the test's clock (no CPG: ``Held.serve_start`` plays its start)."""
    from geometry_msgs.msg import Twist
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu
    from wirefish_common.qos import RELIABLE
    from wirefish_planner.planner_node import PlannerNode

    planner = PlannerNode(context=ros_context, **on_simulated_time(NAMESPACE))
    owner = ClockOwner(ros_context, NAMESPACE, planner)
    imu = owner.node.create_publisher(Imu, 'imu/data', qos_profile_sensor_data)
    cmd_vel = owner.node.create_publisher(Twist, 'cmd_vel', RELIABLE)

    def send_imu(time_ns: int) -> None:
        msg = Imu()
        msg.header.stamp = stamp(time_ns)
        msg.orientation.w = 1.0
        imu.publish(msg)

    def send_cmd_vel(speed: float) -> None:
        msg = Twist()
        msg.linear.x = speed
        cmd_vel.publish(msg)

    try:
        yield Held(owner, send_imu, send_cmd_vel)
    finally:
        owner.close()
        planner.destroy_node()


def _first_answer(held: Held) -> int:
    """Step the clock (with imu/data) until the planner answers a tick; return its next tick."""
    time_ns = ORIGIN_NS

    def answered() -> bool:
        nonlocal time_ns
        if held.answers:
            return True
        time_ns += 10_000_000
        held.send_imu(time_ns)
        held.set_clock(time_ns)
        return False

    assert spin_until(held.executor, answered, 10.0), 'the planner never answered a tick'
    spin_until(held.executor, lambda: False, 0.2)  # every answer of the clock's last step
    return held.answers[-1]


def _commanded(held: Held) -> int:
    """Send the first cmd_vel that asks to move; return the next tick due after it came."""
    due = _first_answer(held)
    held.send_cmd_vel(0.2)
    spin_until(held.executor, lambda: False, 0.3)  # the command is in
    return due


def _tick(held: Held, due: int) -> None:
    """Bring the clock to the tick ``due`` with its imu/data sample."""
    held.send_imu(due)
    held.set_clock(due)


@pytest.mark.ros
def test_each_tick_says_the_next_one_is_due_a_control_period_later(held):
    due = _first_answer(held)
    for _ in range(3):
        _tick(held, due)
        assert spin_until(held.executor, lambda: held.answers[-1] > due, 5.0)
        assert held.answers[-1] == due + TICK_NS
        due = held.answers[-1]
    assert held.owner.holders == {f'{NAMESPACE}/planner_node'}  # a hold per node: its name


@pytest.mark.ros
def test_a_tick_whose_imu_lags_the_clock_waits_for_the_sample(held):
    due = _first_answer(held)
    held.set_clock(due)  # the tick comes, its newest sample 50 ms old
    spin_until(held.executor, lambda: False, 0.3)
    assert held.answers[-1] == due, 'answered without the sample of its tick'
    held.send_imu(due)
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS, 5.0)


@pytest.mark.ros
def test_imu_silent_past_the_wait_stops_holding_the_ticks_until_a_sample_comes(held):
    from wirefish_planner.planner_node import INPUT_WAIT_S

    due = _first_answer(held)
    held.set_clock(due)
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS,
                      INPUT_WAIT_S + 5.0)
    due = held.answers[-1]
    held.set_clock(due)  # still no sample: this tick does not wait
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS, 0.5)
    due = held.answers[-1]
    held.send_imu(due - TICK_NS)  # one came, older than the next tick: that tick waits again
    spin_until(held.executor, lambda: False, 0.2)
    held.set_clock(due)
    spin_until(held.executor, lambda: False, 0.3)
    assert held.answers[-1] == due


@pytest.mark.ros
def test_the_tick_after_the_first_command_answers_once_the_cpg_is_started(held):
    due = _commanded(held)
    _tick(held, due)  # the CPG's start service is not there yet (a graph still discovering)
    spin_until(held.executor, lambda: False, 1.0)
    assert held.answers[-1] == due, 'the clock went on before the CPG was started'
    held.serve_start()
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS, 10.0)
    assert held.start_calls and held.start_calls[0] < len(held.answers), \
        'the tick was answered before the start was called'
    due = held.answers[-1]
    _tick(held, due)  # started: the ticks answer at once again
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS, 1.0)


@pytest.mark.ros
def test_a_start_never_answered_holds_one_tick_for_the_wait_then_the_ticks_go_on(held):
    from wirefish_planner.planner_node import START_WAIT_S

    due = _commanded(held)
    _tick(held, due)
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS,
                      START_WAIT_S + 5.0)
    due = held.answers[-1]
    _tick(held, due)  # the wait ran out: the next tick does not wait again
    assert spin_until(held.executor, lambda: held.answers[-1] == due + TICK_NS, 0.5)
