"""FixedRateLoop: calls at a fixed rate on its own thread, skips (never bursts) when late."""

import os
import sys
import threading
import time

import pytest
from wirefish_cpg.fixed_rate import FixedRateLoop, GIL_SWITCH_INTERVAL_S


def test_tick_is_called_repeatedly_until_stop_and_never_after():
    calls = []
    loop = FixedRateLoop(0.002, lambda: calls.append(time.monotonic()), name='t')
    loop.start()
    deadline = time.monotonic() + 30.0
    while len(calls) < 20 and time.monotonic() < deadline:
        time.sleep(0.01)
    loop.stop()
    stopped_with = len(calls)
    time.sleep(0.05)
    assert stopped_with >= 20
    assert len(calls) == stopped_with


def test_a_late_tick_skips_the_missed_deadlines_instead_of_bursting():
    period = 0.01
    calls = []

    def slow_tick() -> None:
        calls.append(time.monotonic())
        time.sleep(3.5 * period)  # each tick overruns by more than two whole periods

    loop = FixedRateLoop(period, slow_tick, name='t')
    loop.start()
    deadline = time.monotonic() + 30.0
    while len(calls) < 6 and time.monotonic() < deadline:
        time.sleep(0.01)
    loop.stop()
    # Every tick after the first found at least two deadlines passed: skipped, not fired.
    assert loop.missed >= 2 * (len(calls) - 1)
    assert min(b - a for a, b in zip(calls, calls[1:])) >= 3.5 * period


def test_stop_from_inside_the_tick_does_not_deadlock():
    done = threading.Event()
    loop = None

    def tick() -> None:
        loop.stop()
        done.set()

    loop = FixedRateLoop(0.001, tick, name='t')
    loop.start()
    assert done.wait(30.0)


@pytest.mark.parametrize('period', [0.0, -1.0, float('nan')])
def test_a_non_positive_period_is_rejected(period):
    with pytest.raises(ValueError):
        FixedRateLoop(period, lambda: None, name='t')


def test_the_loop_thread_runs_with_the_scheduling_it_reports():
    seen = []
    loop = FixedRateLoop(0.005, lambda: seen.append(os.sched_getscheduler(0)), name='t')
    loop.start()
    deadline = time.monotonic() + 30.0
    while not seen and time.monotonic() < deadline:
        time.sleep(0.01)
    loop.stop()
    expected = os.SCHED_FIFO if loop.scheduling.startswith('SCHED_FIFO') else os.SCHED_OTHER
    assert seen and seen[0] == expected, loop.scheduling
    assert os.sched_getscheduler(0) == os.SCHED_OTHER  # the caller's thread is left alone


def test_the_loop_bounds_how_long_another_thread_keeps_the_gil():
    loop = FixedRateLoop(0.005, lambda: None, name='t')
    loop.start()
    deadline = time.monotonic() + 30.0
    while loop.scheduling == 'not started' and time.monotonic() < deadline:
        time.sleep(0.01)
    loop.stop()
    assert sys.getswitchinterval() <= GIL_SWITCH_INTERVAL_S
