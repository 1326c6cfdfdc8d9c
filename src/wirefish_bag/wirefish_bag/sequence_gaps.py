# SPDX-License-Identifier: Apache-2.0
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

A recording's account of each topic (``TopicAccount``) is kept in the bag as strings
(``recording_account``: metadata.yaml's ``custom_data``, one ``<key>:<topic>`` per figure), and
``loss_line`` is what a run says of it at its end.
"""

from dataclasses import dataclass, field
import enum


class AccountKey(enum.StrEnum):
    """The figures of a topic's account, each kept in custom_data as ``<key>:<topic>``."""

    MISSING = 'missing'  # numbers absent from the publisher's sequence (UNCHECKED: several)
    LAG_MAX = 'lag_max_s'  # the most a message waited between its publication and the bag


# The MISSING figure of a topic that several writers published on (their sequences interleave:
# no count). One word among counts, not a family of values: a plain string.
UNCHECKED = 'unchecked'


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


@dataclass
class TopicAccount:
    """What a recorder took of one topic."""

    count: int = 0
    sequence: SequenceGaps = field(default_factory=SequenceGaps)
    lag_max_ns: int = 0  # take time minus the publisher's source timestamp
    latched: bool = False  # transient-local: a sample may predate the recorder, no lag kept


def recording_account(accounts: dict[str, TopicAccount]) -> dict[str, str]:
    """Return each topic's missing count and worst lag, as the bag's custom_data keeps them."""
    recording = {}
    for topic, account in sorted(accounts.items()):
        sequence = account.sequence
        recording[f'{AccountKey.MISSING}:{topic}'] = (UNCHECKED if sequence.ambiguous
                                                      else str(sequence.missing))
        if not account.latched:
            recording[f'{AccountKey.LAG_MAX}:{topic}'] = f'{account.lag_max_ns * 1e-9:.3f}'
    return recording


def merged_recording(parts: list[dict[str, str]]) -> dict[str, str]:
    """Return several files' accounts as one: missing numbers summed, the worst lag."""
    merged: dict[str, str] = {}
    for part in parts:
        for key, value in part.items():
            kind, _, _ = key.partition(':')
            old = merged.get(key)
            if old is None:
                merged[key] = value
            elif kind == AccountKey.MISSING:
                merged[key] = (UNCHECKED if UNCHECKED in (old, value)
                               else str(int(old) + int(value)))
            elif kind == AccountKey.LAG_MAX:
                merged[key] = str(max(float(old), float(value)))
    return merged


def recording_losses(custom_data: dict | None) -> dict[str, int]:
    """Return {topic: messages missing} of a bag's ``custom_data`` (checked topics only)."""
    losses = {}
    for key, value in (custom_data or {}).items():
        kind, _, topic = str(key).partition(':')
        if kind == AccountKey.MISSING and str(value) != UNCHECKED:
            losses[topic] = int(value)
    return losses


def loss_line(custom_data: dict | None) -> str:
    """Return 'recording: 0 lost ...' or 'recording: LOST n messages: <topic> <count>, ...'."""
    losses = recording_losses(custom_data)
    if not losses and any(str(key).startswith(f'{AccountKey.MISSING}:')
                          for key in (custom_data or {})):
        # An account was written, but of topics with several publishers only: nothing killed.
        return 'recording: loss not counted (every topic has several publishers)'
    if not losses:
        return 'recording: no account of loss (the recorder was killed before it closed the bag)'
    lost = {t: n for t, n in sorted(losses.items()) if n}
    if not lost:
        return f'recording: 0 lost on {len(losses)} topics'
    return (f'recording: LOST {sum(lost.values())} messages: '
            + ', '.join(f'{t} {n}' for t, n in lost.items()))
