# SPDX-License-Identifier: Apache-2.0
"""A timed `wirefish up` on the virtual fish counts the fish's clock, not the wall's."""

from builtin_interfaces.msg import Time
import pytest
from rosgraph_msgs.msg import Clock
from wirefish_launcher.status_view import SimulatedClock
from wirefish_launcher.verb import up as launcher


class _Handle:
    def __init__(self) -> None:
        self.queue: list[Clock] = []

    def take_message(self, _msg_type, _raw):
        return (self.queue.pop(0), None) if self.queue else None


class _Subscription:
    msg_type = Clock

    def __init__(self) -> None:
        self.handle = _Handle()


class _Node:
    def __init__(self) -> None:
        self.subscription = _Subscription()

    def create_subscription(self, *_args):
        return self.subscription


def _publish(node: _Node, *seconds: float) -> None:
    for value in seconds:
        nanoseconds = round(value * 1e9)
        node.subscription.handle.queue.append(
            Clock(clock=Time(sec=nanoseconds // 10**9, nanosec=nanoseconds % 10**9)))


class _Wall:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_the_clock_counts_its_forward_moves_and_not_a_restarts_step_back():
    node = _Node()
    clock = SimulatedClock(node, '/wirefish/clock', wall=_Wall())
    _publish(node, 5.0, 5.5, 6.0, 0.0, 0.25)  # fish_sim restarted after 6.0
    clock.refresh()
    assert clock.advanced == pytest.approx(1.25)


def test_a_timed_run_ends_after_its_simulated_seconds_whatever_the_wall_says(monkeypatch):
    wall = _Wall()
    monkeypatch.setattr(launcher.time, 'monotonic', wall)
    node = _Node()
    clock = SimulatedClock(node, '/wirefish/clock', wall=wall)
    _publish(node, 2.0)  # the clock before the run started is not the run's
    run = launcher._RunTime(clock)
    _publish(node, 2.5, 3.0)
    wall.now += 10.0  # a slow machine: 1 simulated s in 10 wall s
    assert run.elapsed() == pytest.approx(1.0)
    assert run.unit == 'simulated seconds'
    assert not run.stalled()


def test_a_clock_that_stands_still_is_reported_stalled(monkeypatch):
    wall = _Wall()
    monkeypatch.setattr(launcher.time, 'monotonic', wall)
    node = _Node()
    clock = SimulatedClock(node, '/wirefish/clock', wall=wall)
    run = launcher._RunTime(clock)
    _publish(node, 1.0, 1.5)
    wall.now += 1.0
    run.elapsed()
    wall.now += launcher.CLOCK_STALL_S - 0.5
    _publish(node, 1.5)  # a clock that repeats itself does not move
    run.elapsed()
    assert not run.stalled()
    wall.now += 1.0
    assert run.stalled()


def test_without_a_clock_the_run_counts_wall_seconds(monkeypatch):
    wall = _Wall()
    monkeypatch.setattr(launcher.time, 'monotonic', wall)
    run = launcher._RunTime(None)
    wall.now += 7.5
    assert run.elapsed() == pytest.approx(7.5)
    assert run.unit == 'seconds' and not run.stalled()
