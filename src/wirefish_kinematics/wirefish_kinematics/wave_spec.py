# SPDX-License-Identifier: Apache-2.0
"""
The desired body wave of eq 23 as one type, and its wirefish_msgs/BodyWaveSpec converters.

``WaveSpec`` is the wave everywhere in Python: the kinematics node's overlay target (its
``wave_*`` parameters or ``target_wave``), the tuner's fit target (``wirefish_tuner.wave_loss``
re-exports it) and the analysis scripts. The message is its form on the wire. Message types
only, no rclpy.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from wirefish_msgs.msg import BodyWaveSpec

MAX_FREQUENCY_HZ = 10.0


@dataclass(frozen=True)
class WaveSpec:
    """
    A desired Lighthill body wave (eq 23): envelope c1 (m/m), c2 (1/m), k (rad/m), f (Hz).

    The defaults are the paper's section 5.2 case. Raises ``ValueError`` unless all are
    finite, k > 0 and f in (0, 10].
    """

    c1: float = 0.15
    c2: float = 1.0
    k: float = 8.0
    frequency_hz: float = 1.0

    def __post_init__(self) -> None:
        """Coerce every field to float and check the wave is one eq 23 can describe."""
        for name in ('c1', 'c2', 'k', 'frequency_hz'):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value}')
            object.__setattr__(self, name, value)
        if self.k <= 0.0:
            raise ValueError(f'k must be > 0, got {self.k}')
        if not 0.0 < self.frequency_hz <= MAX_FREQUENCY_HZ:
            raise ValueError(f'frequency_hz must be in (0, 10] Hz, got {self.frequency_hz}')


def wave_from_message(msg: BodyWaveSpec) -> WaveSpec:
    """Return the WaveSpec of a BodyWaveSpec (raises ``ValueError`` naming a bad field)."""
    return WaveSpec(msg.c1, msg.c2, msg.k, msg.frequency_hz)


def wave_message(wave: WaveSpec) -> BodyWaveSpec:
    """Return ``wave`` as a wirefish_msgs/BodyWaveSpec."""
    return BodyWaveSpec(c1=wave.c1, c2=wave.c2, k=wave.k, frequency_hz=wave.frequency_hz)
