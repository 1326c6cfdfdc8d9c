# SPDX-License-Identifier: Apache-2.0
"""Progress lines and bars of long commands (pure: a fake clock and a text stream)."""

import io

import pytest
from wirefish_common.progress import (duration_text, end_line, estimate_text, Progress,
                                      progress_text)


class Terminal(io.StringIO):
    """A text stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


class Clock:
    """A clock the test moves."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.mark.parametrize('seconds, text', [
    (4.4, '4 s'), (59.4, '59 s'), (200.0, '3 min 20 s'), (3900.0, '1 h 05 min')])
def test_durations_read_as_a_person_says_them(seconds, text):
    assert duration_text(seconds) == text


@pytest.mark.parametrize('done, total, elapsed, text', [
    (0, 10, 5.0, 'estimating'),
    (2, 10, 10.0, 'about 40 s left'),
    (5, 20, 60.0, 'about 3 min 00 s left'),
    (10, 10, 61.0, 'done in 1 min 01 s'),
])
def test_the_estimate_is_the_time_per_step_times_the_steps_left(done, total, elapsed, text):
    assert estimate_text(done, total, elapsed) == text


def test_a_bar_shows_the_share_done():
    assert progress_text('sweep', 1, 4, 10.0, 'f 2 Hz', bar=True) == (
        'sweep: [######..................] 1/4, about 30 s left | f 2 Hz')


def test_not_on_a_terminal_each_step_is_a_line_with_its_estimate():
    stream, clock = io.StringIO(), Clock()
    progress = Progress('fit', 3, stream=stream, clock=clock)
    for text in ('a', 'b', 'c'):
        clock.now += 2.0
        progress.step(text=text)
    assert stream.getvalue().splitlines() == [
        'fit: 1/3, about 4 s left | a', 'fit: 2/3, about 2 s left | b',
        'fit: 3/3, done in 6 s | c']


def test_not_on_a_terminal_many_steps_give_at_most_one_line_per_twentieth():
    stream = io.StringIO()
    progress = Progress('many', 1000, stream=stream, clock=Clock())
    for _ in range(1000):
        progress.step()
    assert 20 <= len(stream.getvalue().splitlines()) <= 22


def test_on_a_terminal_the_bar_is_redrawn_in_place_and_ends_its_line():
    stream, clock = Terminal(), Clock()
    progress = Progress('fit', 2, stream=stream, clock=clock)
    progress.step(text='a')
    assert '\n' not in stream.getvalue() and stream.getvalue().startswith('\r')
    progress.step(text='b')
    assert stream.getvalue().endswith('| b\n') and stream.getvalue().count('\r') == 2


def test_an_interrupted_bar_gets_its_line_ended():
    stream = Terminal()
    Progress('fit', 5, stream=stream, clock=Clock()).step()
    end_line()
    assert stream.getvalue().endswith('\n')
    end_line()  # nothing left open: nothing more written
    assert stream.getvalue().count('\n') == 1
