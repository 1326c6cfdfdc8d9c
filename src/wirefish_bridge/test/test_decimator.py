# SPDX-License-Identifier: Apache-2.0
"""The battery's decimation: one sample per period, and every change of state at once."""

import pytest
from wirefish_bridge.decimator import Decimator


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
