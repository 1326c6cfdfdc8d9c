# SPDX-License-Identifier: Apache-2.0
"""
Servo command gating of the bridge: rate limit and failsafe (pure, no I/O, no rclpy).

Times are seconds of any monotonic clock. The node calls ``on_command`` for every servo_cmd
message and ``on_tick`` from a timer; each returns the angles to send now, or None.
"""

from __future__ import annotations

NEUTRAL = (0.0, 0.0)


# Frames of credit the rate limit can save up. More than one, so that a command arriving a
# little early (executor jitter) after one a little late is not held: with exactly one, the
# CPG's 200 Hz stream through a 100 Hz gate lost a slot at every early arrival (the next frame
# then went 15 ms after the last). At most this many frames ever go out back to back.
BURST_FRAMES = 1.5


class CommandGate:
    """
    Forward at most ``max_rate_hz`` commands per second and command neutral on silence.

    The rate limit is a token bucket: credit grows at ``max_rate_hz`` frames a second up to
    ``BURST_FRAMES``, and a frame costs one. A command that finds less than one frame of credit
    is held; the next command (which supersedes it: held commands are never queued) or the
    next tick sends the newest held one once the credit is there. When no command arrived for
    ``timeout_s`` (or none ever did) the gate is in failsafe: it returns ``NEUTRAL`` at most
    every ``neutral_period_s`` so a lost frame is repeated.
    """

    def __init__(self, max_rate_hz: float, timeout_s: float, limit_rad: float,
                 neutral_period_s: float = 0.1) -> None:
        """Set the rate limit (Hz), the silence timeout (s) and the angle clamp (rad)."""
        self.max_rate_hz = max_rate_hz
        self.timeout_s = timeout_s
        self.limit_rad = limit_rad
        self.neutral_period_s = neutral_period_s
        self.failsafe = True
        self.failsafe_entries = 0
        self.clamped = 0
        self._last_command_time: float | None = None
        self._last_neutral_time = -float('inf')
        self._credit = 1.0  # frames; the first command goes out at once
        self._credit_time: float | None = None
        self._pending: tuple[float, float] | None = None

    def _clamp(self, angles: tuple[float, float]) -> tuple[float, float]:
        limit = self.limit_rad
        clamped = (min(limit, max(-limit, angles[0])), min(limit, max(-limit, angles[1])))
        if clamped != tuple(angles):
            self.clamped += 1
        return clamped

    def counters(self) -> dict[str, object]:
        """Return the gate's state and counters under their /diagnostics names."""
        return {'failsafe': self.failsafe, 'failsafe_entries': self.failsafe_entries,
                'commands_clamped': self.clamped}

    def on_command(self, angles: tuple[float, float], now: float
                   ) -> tuple[float, float] | None:
        """Take a new command (rad); return it (clamped) if it may go out now, else None."""
        self._last_command_time = now
        self.failsafe = False
        angles = self._clamp(angles)
        if self._take_credit(now):
            self._pending = None
            return angles
        self._pending = angles
        return None

    def _take_credit(self, now: float) -> bool:
        """Spend one frame of credit if there is one (the rate limit); say whether it was."""
        if self._credit_time is not None:
            earned = max(0.0, now - self._credit_time) * self.max_rate_hz
            self._credit = min(BURST_FRAMES, self._credit + earned)
        self._credit_time = now
        if self._credit < 1.0 - 1e-9:  # sums of float steps: 0.3 + 0.3 + 0.2 + 0.2 < 1.0
            return False
        self._credit -= 1.0
        return True

    def on_tick(self, now: float) -> tuple[float, float] | None:
        """Return a held command that may now go out, or NEUTRAL in failsafe, or None."""
        silent = (self._last_command_time is None
                  or now - self._last_command_time > self.timeout_s)
        if silent:
            if not self.failsafe:
                self.failsafe = True
                self.failsafe_entries += 1
                self._last_neutral_time = -float('inf')  # send neutral at once
            self._pending = None
            if now - self._last_neutral_time >= self.neutral_period_s:
                self._last_neutral_time = now
                return NEUTRAL
            return None
        if self._pending is not None and self._take_credit(now):
            angles, self._pending = self._pending, None
            return angles
        return None
