# SPDX-License-Identifier: Apache-2.0
"""
Publish a stream slower than its source, but a change of state at once (pure, no rclpy).

The bridge's ``battery``: the fish sends one TELEMETRY frame 100 times a second, its voltage
changes over minutes, and a change of the low-battery flag goes out with the frame that
carried it. The kinematics node's ``body_wave``: the servo samples decimated by their own
stamps, so a late tick publishes the samples it missed and the rate holds in the samples' time
(the graph's clock, simulated on the virtual fish).
"""

from __future__ import annotations


class Decimator:
    """
    Says which samples of a stream to publish: one per ``1 / rate_hz`` s, and any change.

    The samples due are on a fixed schedule, one period after the last one due: a frame that
    arrives late (a jittery link, a board in an emulator) does not push every later one back,
    so the stream keeps its rate on average. A time before the last one due (a restarted
    clock) starts the schedule again.
    """

    def __init__(self, rate_hz: float) -> None:
        """Publish at most ``rate_hz`` (> 0) samples a second, plus every change."""
        self.rate_hz = rate_hz
        self._next_time: float | None = None
        self._last_due: float | None = None
        self._last_state: object = None

    @property
    def rate_hz(self) -> float:
        """Return the rate (Hz); a new one applies from the next sample."""
        return self._rate_hz

    @rate_hz.setter
    def rate_hz(self, value: float) -> None:
        if not value > 0.0:
            raise ValueError(f'rate must be > 0 Hz, got {value}')
        self._rate_hz = float(value)

    def due(self, now: float, state: object = None) -> bool:
        """Return whether the sample at ``now`` (s) with ``state`` is published."""
        period = 1.0 / self._rate_hz
        if self._last_due is not None and now < self._last_due:
            self._next_time = None  # the clock went back
        changed = self._next_time is not None and state != self._last_state
        # Within a hundredth of a period counts as on time: 100 Hz frames against 10 Hz must
        # give every tenth frame, not every eleventh when a frame comes a little early.
        if (self._next_time is None or changed
                or now >= self._next_time - 0.01 * period):
            # After a gap of more than a period (or a change) the schedule starts again at now.
            start = now
            if self._next_time is not None and not changed and now - self._next_time < period:
                start = self._next_time
            self._next_time = start + period
            self._last_due = now
            self._last_state = state
            return True
        return False
