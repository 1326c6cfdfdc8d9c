# SPDX-License-Identifier: Apache-2.0
"""Decimation by time: one sample per period, every change of state at once, restarts."""

import pytest
from wirefish_common.decimator import Decimator


def _published(decimator: Decimator, times: list[float], states: list[object]) -> list[float]:
    return [t for t, s in zip(times, states) if decimator.due(t, s)]


def test_100_hz_frames_give_every_tenth_at_10_hz_even_with_early_frames():
    times = [0.01 * n - (0.0002 if n % 3 == 0 else 0.0) for n in range(1000)]
    published = _published(Decimator(10.0), times, [False] * 1000)
    assert len(published) == 100
    assert max(b - a for a, b in zip(published, published[1:])) < 0.1 + 0.0003


def test_late_frames_do_not_slow_the_rate_down():
    # 100 Hz frames, each 0 to 9 ms late (a jittery link): still 10 a second on average
    # (publishing a period after the last publish gave 91).
    times = [0.01 * n + 0.0009 * ((n * 37) % 11) for n in range(1000)]
    published = _published(Decimator(10.0), times, [False] * 1000)
    assert len(published) == 100


def test_a_change_of_state_goes_out_at_once_and_a_steady_one_at_the_rate():
    times = [0.01 * n for n in range(30)]
    states = [False] * 15 + [True] * 15  # the low-battery flag rises at 0.15 s
    published = _published(Decimator(10.0), times, states)
    assert published == pytest.approx([0.0, 0.1, 0.15, 0.25])


@pytest.mark.parametrize('rate', [0.0, -1.0, float('nan')])
def test_a_rate_that_is_not_positive_is_refused(rate):
    with pytest.raises(ValueError):
        Decimator(rate)


def test_a_clock_that_goes_back_starts_the_schedule_again():
    times = [100.0 + 0.01 * n for n in range(50)] + [0.01 * n for n in range(50)]
    published = _published(Decimator(50.0), times, [False] * 100)
    assert len(published) == 50
    assert published[25] == pytest.approx(0.0)  # the restarted clock's first sample


def test_late_samples_taken_in_one_batch_keep_every_due_one():
    # A consumer that takes its queue late gets the samples in a batch: their own stamps
    # decide, so 100 Hz samples give exactly 50 a second however they were taken.
    times = [0.01 * n for n in range(500)]
    assert len(_published(Decimator(50.0), times, [False] * 500)) == 250
