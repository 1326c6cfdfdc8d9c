# SPDX-License-Identifier: Apache-2.0
"""The executor choice (WIREFISH_EXECUTOR) and the one spin loop, without ROS."""

import pytest
from wirefish_common.executors import (executor_kind, EXECUTOR_VARIABLE, ExecutorKind,
                                       make_executor, settle, spin_until_stopped, wake)

EVENTS, CLASSIC = ExecutorKind.EVENTS, ExecutorKind.CLASSIC


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


class Context:
    """A context that records every ``ok()`` asked of it."""

    def __init__(self) -> None:
        self.asked = 0

    def ok(self) -> bool:
        self.asked += 1
        return True


class FakeExecutor:
    def __init__(self) -> None:
        self.context = Context()
        self.spins = 0
        self.tasks = []

    def spin_once(self, timeout_sec: float) -> None:
        self.spins += 1

    def create_task(self, callback) -> None:
        self.tasks.append(callback)


def test_spin_until_stopped_spins_until_the_flag_is_set():
    executor = FakeExecutor()
    spin_until_stopped(executor, lambda: executor.spins == 3)
    assert executor.spins == 3


def test_spin_until_stopped_asks_the_context_nothing_between_callbacks():
    # A context.ok() per callback was 15 % of the bridge's Python samples: the stop flag and
    # spin_once's own error on a shut-down context are all the loop looks at.
    executor = FakeExecutor()
    spin_until_stopped(executor, lambda: executor.spins == 100)
    assert executor.context.asked == 0


class ShutDown(Exception):
    pass


class EndingExecutor(FakeExecutor):
    def spin_once(self, timeout_sec: float) -> None:
        super().spin_once(timeout_sec)
        if self.spins == 2:  # as rclpy's executors do once their context is shut down
            raise ShutDown


def test_spin_until_stopped_ends_when_spin_once_raises_on_a_shut_down_context():
    executor = EndingExecutor()
    # The flag stops a loop that swallowed the error at 10 spins: the test fails, not hangs.
    with pytest.raises(ShutDown):
        spin_until_stopped(executor, lambda: executor.spins >= 10)
    assert executor.spins == 2


def test_wake_hands_the_executor_a_task_that_does_nothing():
    executor = FakeExecutor()
    wake(executor)
    assert len(executor.tasks) == 1 and executor.tasks[0]() is None


class QueueExecutor(FakeExecutor):
    """Runs one queued task per spin, in order, as both rclpy executors do."""

    def spin_once(self, timeout_sec: float) -> None:
        super().spin_once(timeout_sec)
        if self.tasks:
            self.tasks.pop(0)()


def test_settle_spins_until_the_work_queued_before_it_has_run():
    executor = QueueExecutor()
    ran = []
    for index in range(3):  # callbacks already waiting: each takes one spin
        executor.create_task(lambda index=index: ran.append(index))
    assert settle(executor) is True
    assert ran == [0, 1, 2] and executor.spins == 4


def test_settle_says_false_when_the_time_runs_out_first():
    executor = FakeExecutor()  # never runs its tasks
    assert settle(executor, timeout_s=0.05) is False
