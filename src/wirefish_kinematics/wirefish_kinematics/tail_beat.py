# SPDX-License-Identifier: Apache-2.0
"""
The last full tail-beat period in a stream of timestamped servo samples, and its estimate.

The node receives servo angles at uneven instants (header stamps). A period is the interval
between the two latest upward crossings of the tail tip's lateral position through the middle
of its range; noise cannot split one crossing into several because a crossing only counts after
the signal went below the middle by a quarter of the half range (hysteresis). The samples of
that interval are then linearly resampled onto a uniform grid for eqs 16-22.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike

from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import estimate_speed, SpeedEstimate

HYSTERESIS_FRACTION = 0.25  # of the half range, below the middle, to arm the next crossing
RESAMPLED_SAMPLES = 128  # uniform samples per period handed to eqs 16-22


@dataclass(frozen=True)
class TailBeat:
    """The last full tail-beat period: start and end (s)."""

    start: float
    end: float

    @property
    def period(self) -> float:
        """Return the duration of the tail beat (s)."""
        return self.end - self.start

    @property
    def frequency_hz(self) -> float:
        """Return the tail-beat frequency (Hz)."""
        return 1.0 / self.period


def upward_crossings(times: ArrayLike, signal: ArrayLike) -> np.ndarray:
    """
    Return the instants (s) where ``signal`` rises through the middle of its range, (C,).

    ``times`` (T,) strictly increasing s; crossings are interpolated linearly between samples
    and counted once per cycle (see the module docstring).
    """
    t = np.asarray(times, dtype=float)
    s = np.asarray(signal, dtype=float)
    middle = 0.5 * (s.max() + s.min())
    arm_below = middle - HYSTERESIS_FRACTION * 0.5 * (s.max() - s.min())
    rising = np.flatnonzero((s[:-1] < middle) & (s[1:] >= middle)) + 1
    below = np.flatnonzero(s < arm_below)
    crossings = []
    armed_after = -1  # index of the previous accepted crossing
    for i in rising:
        # armed if the signal went below the arming level since the previous crossing
        k = np.searchsorted(below, armed_after, side='right')
        if k < below.size and below[k] < i:
            fraction = (middle - s[i - 1]) / (s[i] - s[i - 1])
            crossings.append(t[i - 1] + fraction * (t[i] - t[i - 1]))
            armed_after = int(i)
    return np.array(crossings)


def resample(times: ArrayLike, values: ArrayLike, start: float, end: float,
             samples: int = RESAMPLED_SAMPLES) -> tuple[np.ndarray, float]:
    """
    Return ``values`` (T, ...) linearly interpolated at start + n dt, n < samples, and dt (s).

    The end point is excluded (it is the next period's start), as the rectangle rule needs.
    """
    t = np.asarray(times, dtype=float)
    v = np.asarray(values, dtype=float)
    dt = (end - start) / samples
    grid = start + dt * np.arange(samples)
    flat = v.reshape(v.shape[0], -1)
    out = np.stack([np.interp(grid, t, column) for column in flat.T], axis=-1)
    return out.reshape((samples,) + v.shape[1:]), dt


def last_tail_beat(times: ArrayLike, signal: ArrayLike, min_half_range: float
                   ) -> TailBeat | None:
    """
    Return the last full period of ``signal`` (T,) at ``times`` (T,) s, or None.

    None when the signal's half range is below ``min_half_range`` (at rest) or fewer than two
    crossings are in the samples.
    """
    s = np.asarray(signal, dtype=float)
    if s.size < 3 or 0.5 * np.ptp(s) < min_half_range:
        return None
    crossings = upward_crossings(times, s)
    if crossings.size < 2:
        return None
    return TailBeat(start=float(crossings[-2]), end=float(crossings[-1]))


def fundamental_phase(times: ArrayLike, signal: ArrayLike, beat: TailBeat, t: ArrayLike
                      ) -> np.ndarray:
    """
    Return the phase p(t) (rad) of ``signal``'s fundamental over ``beat``, at times t (s).

    signal ~ mean + a cos(p(t)) with p(t) = 2 pi (t - start) / period + psi, psi from the
    discrete Fourier coefficient over the period; extrapolated periodically beyond it.
    """
    uniform, _ = resample(times, signal, beat.start, beat.end)
    grid = 2.0 * math.pi * np.arange(uniform.shape[0]) / uniform.shape[0]
    psi = float(np.angle(np.sum(uniform * np.exp(-1j * grid))))
    return 2.0 * math.pi * (np.asarray(t, dtype=float) - beat.start) / beat.period + psi


def estimate_speed_over(times: ArrayLike, servo_angles: ArrayLike, servo_rates: ArrayLike,
                        start: float, end: float, geometry: FishGeometry,
                        samples: int = RESAMPLED_SAMPLES) -> SpeedEstimate:
    """
    Return the eq 16-22 estimate over [start, end) s of samples at uneven ``times`` (T,).

    ``servo_angles``, ``servo_rates`` (T, 2) rad, rad/s are resampled to ``samples`` uniform
    instants. Rates containing NaN (a source without velocities) are replaced by the
    central differences of the angles.
    """
    t = np.asarray(times, dtype=float)
    angles = np.asarray(servo_angles, dtype=float)
    rates = np.asarray(servo_rates, dtype=float)
    if np.isnan(rates).any():
        rates = np.gradient(angles, t, axis=0)
    uniform_angles, dt = resample(t, angles, start, end, samples)
    uniform_rates, _ = resample(t, rates, start, end, samples)
    return estimate_speed(uniform_angles, uniform_rates, dt, geometry)
