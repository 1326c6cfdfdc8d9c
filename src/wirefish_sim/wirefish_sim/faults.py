# SPDX-License-Identifier: Apache-2.0
"""
Fault injection of the virtual fish's serial output (pure; randomness from a Generator).

``corrupt_fraction``: each byte is replaced (xor with a random non-zero value) with that
probability; ``drop_fraction``: each frame is dropped whole with that probability (its sequence
number is used, so the receiver sees a gap).

``Disturbance`` (not a link fault: the water's): a constant yaw disturbance (a current that
turns the fish, ``yaw_rate_rad_s`` = the yaw rate it gives a straight-swimming fish) and a
constant surge force (``surge_force_n``, + pushes forward), applied to the fish's state after each
physics step (``disturb``).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

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


@dataclass(frozen=True)
class Disturbance:
    """A constant yaw disturbance (rad/s) and surge force (N) on the virtual fish."""

    yaw_rate_rad_s: float = 0.0
    surge_force_n: float = 0.0

    def __post_init__(self) -> None:
        """Check both values are finite."""
        for name in ('yaw_rate_rad_s', 'surge_force_n'):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f'{name} must be finite, got {getattr(self, name)}')

    @property
    def active(self) -> bool:
        """Return whether either disturbance is not 0."""
        return self.yaw_rate_rad_s != 0.0 or self.surge_force_n != 0.0


def disturb(state, disturbance: Disturbance, dt: float, yaw_time_constant_s: float,
            total_mass: float) -> None:
    """
    Apply ``disturbance`` over ``dt`` s to a ``FishState`` (speed, yaw_rate) in place.

    Yaw: the fish's yaw rate relaxes with its time constant tau towards its own target plus
    the disturbance, d r / dt += d / tau, so a straight fish settles at r = d. Surge: the force
    acts on the surge inertia ``total_mass`` (kg) beside thrust and drag, so a steady fish
    settles where F_T = F_D - F_surge.
    """
    state.yaw_rate += dt * disturbance.yaw_rate_rad_s / yaw_time_constant_s
    state.speed += dt * disturbance.surge_force_n / total_mass
