# SPDX-License-Identifier: Apache-2.0
"""The answer pacer: slots at least one interval apart, the work outside the pacing."""

import pytest
from wirefish_tuner.answered_service import AnswerPacer, paced


class FakeClock:
    """A clock that moves only when slept on (or when a callback does work)."""

    def __init__(self) -> None:
        self.now = 100.0
        self.slept: list[float] = []

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.slept.append(seconds)
        self.now += seconds


def test_answers_at_once_are_spaced_one_interval_apart():
    clock = FakeClock()
    pacer = AnswerPacer(0.02, clock=clock, sleep=clock.sleep)
    for _ in range(3):
        pacer.wait_for_slot()
    assert clock.slept == pytest.approx([0.02, 0.02])


def test_an_answer_after_the_interval_is_not_delayed():
    clock = FakeClock()
    pacer = AnswerPacer(0.02, clock=clock, sleep=clock.sleep)
    pacer.wait_for_slot()
    clock.now += 0.5
    pacer.wait_for_slot()
    assert clock.slept == []


def test_a_paced_callback_returns_what_the_callback_answered():
    clock = FakeClock()
    answer = paced(lambda request, response: response + [request],
                   AnswerPacer(0.02, clock=clock, sleep=clock.sleep))
    assert answer('a', []) == ['a']
    assert answer('b', []) == ['b']
    assert clock.slept == pytest.approx([0.02])


def test_work_longer_than_the_interval_is_not_delayed_further():
    clock = FakeClock()

    def slow(request, response):
        clock.now += 1.0  # a fit: far longer than the interval
        return response

    answer = paced(slow, AnswerPacer(0.02, clock=clock, sleep=clock.sleep))
    answer(None, 1)
    answer(None, 2)
    assert clock.slept == []
