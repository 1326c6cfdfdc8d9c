"""
Fault injection of the virtual fish's serial output (pure; randomness from a Generator).

``corrupt_fraction``: each byte is replaced (xor with a random non-zero value) with that
probability; ``drop_fraction``: each frame is dropped whole with that probability (its sequence
number is used, so the receiver sees a gap).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class FaultCounters:
    """How many frames were dropped and bytes corrupted so far."""

    frames_dropped: int = 0
    bytes_corrupted: int = 0


class FaultInjector:
    """Applies the configured faults to outgoing frames."""

    def __init__(self, rng: np.random.Generator, corrupt_fraction: float = 0.0,
                 drop_fraction: float = 0.0) -> None:
        """Check fractions are in [0, 1]."""
        for name, value in (('corrupt_fraction', corrupt_fraction),
                            ('drop_fraction', drop_fraction)):
            if not 0.0 <= value <= 1.0:
                raise ValueError(f'{name} must be in [0, 1], got {value}')
        self.rng = rng
        self.corrupt_fraction = corrupt_fraction
        self.drop_fraction = drop_fraction
        self.counters = FaultCounters()

    def apply(self, frames: list[bytes]) -> bytes:
        """Return the bytes to send for ``frames`` after dropping and corrupting."""
        kept = []
        for frame in frames:
            if self.drop_fraction and self.rng.random() < self.drop_fraction:
                self.counters.frames_dropped += 1
                continue
            kept.append(frame)
        data = b''.join(kept)
        if not self.corrupt_fraction or not data:
            return data
        buffer = np.frombuffer(data, dtype=np.uint8).copy()
        hit = self.rng.random(buffer.size) < self.corrupt_fraction
        count = int(hit.sum())
        buffer[hit] ^= self.rng.integers(1, 256, count, dtype=np.uint8)
        self.counters.bytes_corrupted += count
        return buffer.tobytes()
