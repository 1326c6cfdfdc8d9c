# SPDX-License-Identifier: Apache-2.0
"""
The graph's time as the bridge's gate, link health, decimation and gait link count it (pure).

Those cores take times as seconds of a clock that never goes back. The bridge reads the node
clock: the wall clock on the real-time roads, the virtual fish's simulated time under
``use_sim_time`` (so a rate limit, a command timeout or a heartbeat age is judged in the time the
graph runs on, not in the wall time a loaded machine took to run it). Simulated time goes back
when the fish_sim that owns it restarts; ``GraphTime`` then carries on from where it was, so a
jump back of the clock is a pause of no length, never a negative age or a schedule that waits
for the old time to come round again. Only the serial reader's own I/O timeouts stay on the
wall clock (transport.py): there real time is the claim.
"""

from __future__ import annotations

import threading


class GraphTime:
    """
    Monotonic seconds from a clock that may jump back: t = clock + offset.

    ``offset`` grows by the size of each backward jump (t_k = max over the readings so far
    of the continued clock), so t never decreases and advances exactly as the clock does
    between jumps. Thread-safe: the serial reader and the executor both read it.
    """

    def __init__(self) -> None:
        """Start with no reading (the first one is taken as it is)."""
        self._lock = threading.Lock()
        self._offset_s = 0.0
        self._last_s: float | None = None
        self.jumps_back = 0

    def __call__(self, clock_s: float) -> float:
        """Return the monotonic time (s) of the clock reading ``clock_s`` (s)."""
        with self._lock:
            t = clock_s + self._offset_s
            if self._last_s is not None and t < self._last_s:
                self._offset_s += self._last_s - t
                self.jumps_back += 1
                t = self._last_s
            self._last_s = t
            return t
