"""The executor choice (WIREFISH_EXECUTOR) and the one spin loop, without ROS."""

import pytest
from wirefish_common.executors import (CLASSIC, EVENTS, executor_kind, EXECUTOR_VARIABLE,
                                       make_executor, spin_until_stopped, wake)


@pytest.mark.parametrize(('environ', 'kind'), [
    ({}, EVENTS), ({EXECUTOR_VARIABLE: ''}, EVENTS), ({EXECUTOR_VARIABLE: 'events'}, EVENTS),
    ({EXECUTOR_VARIABLE: 'classic'}, CLASSIC), ({EXECUTOR_VARIABLE: ' classic\n'}, CLASSIC)])
def test_executor_kind_reads_the_variable_and_defaults_to_events(environ, kind):
    assert executor_kind(environ) == kind


@pytest.mark.parametrize('value', ['Events', 'multi', 'single', 'classic,events'])
def test_an_unknown_executor_is_refused_naming_the_variable_and_the_choices(value):
    with pytest.raises(ValueError, match=rf"{EXECUTOR_VARIABLE}='{value}'.*events, classic"):
        executor_kind({EXECUTOR_VARIABLE: value})


def test_make_executor_refuses_an_unknown_kind():
    with pytest.raises(ValueError, match='unknown executor kind'):
        make_executor('multi')


class FakeContext:
    def __init__(self, ok_calls: int) -> None:
        self.ok_calls = ok_calls

    def ok(self) -> bool:
        self.ok_calls -= 1
        return self.ok_calls >= 0


class FakeExecutor:
    def __init__(self, context: FakeContext) -> None:
        self.context = context
        self.spins = 0
        self.tasks = []

    def spin_once(self, timeout_sec: float) -> None:
        self.spins += 1

    def create_task(self, callback) -> None:
        self.tasks.append(callback)


def test_spin_until_stopped_spins_until_the_flag_is_set():
    executor = FakeExecutor(FakeContext(ok_calls=100))
    spin_until_stopped(executor, lambda: executor.spins == 3)
    assert executor.spins == 3


class ShutDown(Exception):
    pass


class EndingExecutor(FakeExecutor):
    def spin_once(self, timeout_sec: float) -> None:
        super().spin_once(timeout_sec)
        if self.spins == 2:  # as rclpy's executors do once their context is shut down
            raise ShutDown


def test_spin_until_stopped_ends_when_spin_once_raises_on_a_shut_down_context():
    executor = EndingExecutor(FakeContext(ok_calls=100))
    with pytest.raises(ShutDown):
        spin_until_stopped(executor, lambda: False)
    assert executor.spins == 2


def test_wake_hands_the_executor_a_task_that_does_nothing():
    executor = FakeExecutor(FakeContext(ok_calls=1))
    wake(executor)
    assert len(executor.tasks) == 1 and executor.tasks[0]() is None
