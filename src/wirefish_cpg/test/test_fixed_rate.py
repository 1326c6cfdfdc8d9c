"""FixedRateLoop: calls at a fixed rate on its own thread, skips (never bursts) when late."""

import threading
import time

import pytest
from wirefish_cpg.fixed_rate import FixedRateLoop


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
