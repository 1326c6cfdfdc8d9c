# SPDX-License-Identifier: Apache-2.0
"""A bounded, time-ordered history of servo samples (angles, rates) for the tail-beat window."""

from __future__ import annotations

from collections import deque
import math

import numpy as np


class ServoHistory:
    """
    Samples (t s, angles (2,) rad, rates (2,) rad/s) of the last ``span_s`` seconds.

    Times are kept relative to ``origin_s`` (the first sample's whole second) so that float64
    keeps nanosecond resolution with epoch stamps. Rates may be NaN (source without velocity).
    """

    def __init__(self, span_s: float) -> None:
        """Create an empty history keeping ``span_s`` seconds (> 0)."""
        self.span_s = float(span_s)
        self.origin_s: int | None = None
        self._samples: deque[tuple[float, float, float, float, float]] = deque()

    def clear(self) -> None:
        """Forget every sample (and the time origin)."""
        self._samples.clear()
        self.origin_s = None

    def add(self, sec: int, nanosec: int, angles: tuple[float, float],
            rates: tuple[float, float]) -> bool:
        """
        Append a sample stamped (sec, nanosec); return False if it was not appended.

        A stamp not after the last one is ignored (duplicate or reordered sample), except a
        jump back by more than ``span_s`` (a restarted clock), which starts a new history.
        """
        if self.origin_s is None:
            self.origin_s = int(sec)
        t = (int(sec) - self.origin_s) + 1e-9 * int(nanosec)
        if self._samples and t <= self._samples[-1][0]:
            if t >= self._samples[-1][0] - self.span_s:
                return False
            self.clear()
            return self.add(sec, nanosec, angles, rates)
        self._samples.append((t, *angles, *rates))
        while self._samples[0][0] < t - self.span_s:
            self._samples.popleft()
        return True

    def __len__(self) -> int:
        """Return the number of samples kept."""
        return len(self._samples)

    def duration_s(self) -> float:
        """Return the time between the first and the last sample kept (s)."""
        return self._samples[-1][0] - self._samples[0][0] if self._samples else 0.0

    def last_time(self) -> float:
        """Return the time of the last sample (s, relative to origin_s); 0 if empty."""
        return self._samples[-1][0] if self._samples else 0.0

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return (times (T,) s relative to origin_s, angles (T, 2) rad, rates (T, 2) rad/s)."""
        data = np.array(self._samples, dtype=float).reshape(-1, 5)
        return data[:, 0], data[:, 1:3], data[:, 3:5]

    def stamp_of(self, t: float) -> tuple[int, int]:
        """Return the (sec, nanosec) stamp of a relative time t (s)."""
        whole = math.floor(t)
        nanosec = int(round((t - whole) * 1e9))
        if nanosec >= 1_000_000_000:
            whole, nanosec = whole + 1, nanosec - 1_000_000_000
        return (self.origin_s or 0) + whole, nanosec
