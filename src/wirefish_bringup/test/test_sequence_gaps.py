"""SequenceGaps counts exactly the samples absent from a publisher's sequence numbers."""

import pytest
from wirefish_bringup.sequence_gaps import SequenceGaps


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
