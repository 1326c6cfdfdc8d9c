"""
Count the messages a subscriber never received, from the publisher's sequence numbers.

Every DDS writer numbers its samples 1, 2, 3, ... (rmw passes the number on as the message
info's ``publication_sequence_number``). A subscriber that sees 7 after 5 has missed exactly one
sample, whatever the reason: lost in transport, overwritten in a queue, or dropped by a slow
reader. That is a count, not a timing estimate, so it answers "did the bag lose anything?"
exactly, where gaps in the header stamps also hold timer ticks that a starved publisher skipped
(it sent nothing then, so nothing was lost).

Sequence numbers belong to one writer; a topic with several publishers interleaves several
sequences, so its count is only exact while one publisher is seen (``ambiguous`` says when not).
"""

from dataclasses import dataclass


@dataclass
class SequenceGaps:
    """The sequence numbers of one topic's samples as they arrive, in arrival order."""

    received: int = 0
    missing: int = 0
    # A number at or below the last one: a new writer (publisher restarted, or a second one).
    restarts: int = 0
    _last: int | None = None

    def add(self, sequence_number: int | None) -> None:
        """Account for one received sample; ``None`` (no number from the rmw) counts only."""
        self.received += 1
        if sequence_number is None:
            return
        if self._last is not None:
            if sequence_number > self._last:
                self.missing += sequence_number - self._last - 1
            else:
                self.restarts += 1
        self._last = sequence_number

    @property
    def ambiguous(self) -> bool:
        """Return True when another writer appeared, so ``missing`` may be off."""
        return self.restarts > 0
