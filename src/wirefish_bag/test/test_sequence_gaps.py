# SPDX-License-Identifier: Apache-2.0
"""SequenceGaps counts the samples absent from a publisher's sequence numbers; a run says so."""

from pathlib import Path

import pytest
from wirefish_bag.sequence_gaps import recording_account, SequenceGaps, TopicAccount
from wirefish_bag.verb.record import recording_summary


def _gaps(numbers: list[int | None]) -> SequenceGaps:
    gaps = SequenceGaps()
    for number in numbers:
        gaps.add(number)
    return gaps


@pytest.mark.parametrize('numbers, missing', [
    ([1, 2, 3, 4], 0),
    ([5, 6, 7], 0),  # a late subscriber starts wherever the writer is
    ([1, 2, 5, 6], 2),
    ([1, 3, 5, 10], 1 + 1 + 4),
    ([], 0),
])
def test_missing_counts_the_absent_numbers(numbers, missing):
    assert _gaps(numbers).missing == missing


def test_every_sample_counts_as_received_even_without_a_number():
    gaps = _gaps([1, None, 2])
    assert (gaps.received, gaps.missing) == (3, 0)


def test_a_number_going_back_is_a_new_writer_not_a_loss():
    gaps = _gaps([7, 8, 1, 2])
    assert (gaps.missing, gaps.restarts, gaps.ambiguous) == (0, 1, True)


def test_one_writer_in_order_is_not_ambiguous():
    assert not _gaps([1, 2, 4]).ambiguous


def _account(numbers: list[int | None], latched: bool = False) -> TopicAccount:
    return TopicAccount(len(numbers), _gaps(numbers), 250_000_000, latched)


def test_a_recording_that_lost_names_each_topic_and_count_in_its_last_line():
    accounts = {'/a': _account([1, 2, 5]), '/b': _account([1, 2, 3]),
                '/c': _account([4, 9], latched=True), '/d': _account([3, 1])}
    text = recording_summary(Path('bag'), accounts)
    assert text.splitlines()[-1] == 'recording: LOST 6 messages: /a 2, /c 4'
    assert '/d' in text and 'several publishers: sequence not checked' in text


def test_a_recording_that_lost_nothing_says_so():
    text = recording_summary(Path('bag'), {'/a': _account([1, 2, 3])})
    assert text.splitlines()[-1] == 'recording: 0 lost on 1 topics'
    assert 'lag max 0.25 s' in text


def test_a_latched_topic_keeps_no_lag_in_the_account():
    account = recording_account({'/a': _account([1]), '/c': _account([1], latched=True)})
    assert account == {'missing:/a': '0', 'lag_max_s:/a': '0.250', 'missing:/c': '0'}
