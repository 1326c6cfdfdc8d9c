# SPDX-License-Identifier: Apache-2.0
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
    # The third tick takes 2.5 periods: the deadlines 4 and 5 pass while it runs. The loop
    # fires the latest one at once (deadline 4 is counted as missed) and is back on its grid
    # at deadline 6, half a period later. A loop that fired every missed deadline would call
    # twice at once: nothing in the loop's own timing puts the two calls apart.
    period = 0.05
    calls = []
    slow_tick_returned = []

    def tick() -> None:
        calls.append(time.monotonic())
        if len(calls) == 3:
            time.sleep(2.5 * period)
            slow_tick_returned.append(time.monotonic())

    loop = FixedRateLoop(period, tick, name='t')
    loop.start()
    deadline = time.monotonic() + 30.0
    while len(calls) < 6 and time.monotonic() < deadline:
        time.sleep(0.01)
    loop.stop()
    after = [t for t in calls if t >= slow_tick_returned[0]]
    assert after[1] - after[0] >= 0.25 * period, [round((t - calls[0]) / period, 2)
                                                  for t in calls]
    assert loop.missed >= 1


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
    # Python's default interval: an earlier loop of this process may have lowered it already.
    before = sys.getswitchinterval()
    sys.setswitchinterval(0.005)
    try:
        loop = FixedRateLoop(0.005, lambda: None, name='t')
        loop.start()
        deadline = time.monotonic() + 30.0
        while loop.scheduling == 'not started' and time.monotonic() < deadline:
            time.sleep(0.01)
        loop.stop()
        assert sys.getswitchinterval() <= GIL_SWITCH_INTERVAL_S
    finally:
        sys.setswitchinterval(before)
