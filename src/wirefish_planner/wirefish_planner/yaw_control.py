# SPDX-License-Identifier: Apache-2.0
"""
Turning by the CPG offsets b_1 = b_2 = b (paper eq 1's b_i): yaw-rate PI and heading hold (pure).

Plant (the virtual fish's yaw model, ``wirefish_sim.fish_dynamics``; a straight-tail assumption
for a real fish): the steady yaw rate is proportional to the forward speed U and to the tail's
mean lateral offset, which is proportional to b, so r = k U b with k the turn gain
(rad/s per rad of offset per m/s; negative when a tail held right, b > 0, turns right).

Controller, on each IMU sample with the real dt between message stamps::

    e   = r_ref - r_meas                       (r_meas: mean over one tail-beat period)
    I  += k_i e dt                             (only while the output is not saturated
                                                in the direction e pushes: anti-windup)
    b   = clip((r_ref + k_p e + I) / (k U), +-b_max)   (feed-forward r_ref / (k U) + PI)

Heading hold (angular.z = 0): r_ref = clip(k_h wrap(psi_target - psi_mean), +-r_hold_max), with
psi from the IMU orientation. The period means remove the head's yaw oscillation at the
tail-beat frequency, which would otherwise drive the offsets at that frequency.

The turn gain k is a parameter; ``identify_turn_gain`` estimates it (and a constant yaw
disturbance d) from a run's steady stretches (``steady_means``: 1 s means where b held still;
the transients after a change of b would bias k towards 0), r = k U b + d by least squares.
`wirefish mission` fits it to per-leg means of the planner_state it recorded and judges the
fit before calling it usable (``wirefish_operator.mission_report``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
import math

import numpy as np

MIN_TURNING_SPEED_M_S = 0.01  # below this the tail cannot turn the fish (r = k U b)


def wrap_angle(angle: float) -> float:
    """Return ``angle`` wrapped into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Return the yaw (rad, about z up, REP-103) of a unit quaternion (ZYX Euler angles)."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def heading_rate_reference(heading_target: float, heading: float, gain: float,
                           limit: float) -> float:
    """Return the yaw-rate reference of the heading hold: clip(k_h wrap(target - psi), +-r)."""
    return min(limit, max(-limit, gain * wrap_angle(heading_target - heading)))


def feedforward_offset(yaw_rate: float, speed: float, turn_gain: float) -> float:
    """Return the offset b (rad) of the plant model r = k U b for ``yaw_rate`` (0 if U ~ 0)."""
    if speed < MIN_TURNING_SPEED_M_S or turn_gain == 0.0:
        return 0.0
    return yaw_rate / (turn_gain * speed)


class PeriodMean:
    """Mean of the samples of the last ``window_s`` seconds of their own stamps."""

    def __init__(self, window_s: float) -> None:
        """Start empty with a window of ``window_s`` s (> 0)."""
        self.window_s = window_s
        self._samples: deque[tuple[float, float]] = deque()
        self._sum = 0.0

    def add(self, stamp_s: float, value: float) -> float:
        """Add a sample and return the mean over the window ending at ``stamp_s``."""
        self._samples.append((stamp_s, value))
        self._sum += value
        while self._samples and self._samples[0][0] <= stamp_s - self.window_s:
            self._sum -= self._samples.popleft()[1]
        return self._sum / len(self._samples)

    def clear(self) -> None:
        """Forget every sample."""
        self._samples.clear()
        self._sum = 0.0


@dataclass(frozen=True)
class YawGains:
    """Gains and limits of the yaw controller (see the module docstring)."""

    turn_gain: float = -9.25  # rad/s per rad per m/s: the virtual fish's yaw model
    kp: float = 0.5
    ki: float = 0.8  # 1/s
    max_offset_rad: float = 0.3
    integral_limit: float = 0.5  # rad/s: the largest disturbance the integrator may cancel
    heading_gain: float = 0.8  # 1/s
    max_hold_rate: float = 0.3  # rad/s

    def __post_init__(self) -> None:
        """Check the values are finite; the gain must not be 0, the others not negative."""
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value}')
            if name != 'turn_gain' and value < 0.0:
                raise ValueError(f'{name} must be >= 0, got {value}')
        if self.turn_gain == 0.0:
            raise ValueError('turn_gain must not be 0 (the offset would not turn the fish)')


class YawRatePi:
    """The yaw-rate PI with feed-forward, anti-windup and output limits (module docstring)."""

    def __init__(self, gains: YawGains) -> None:
        """Start with an empty integrator."""
        self.gains = gains
        self.integral = 0.0
        self.offset = 0.0
        self.saturated = False

    def reset(self) -> None:
        """Empty the integrator and return the output to 0 (rest, or a released hold)."""
        self.integral = 0.0
        self.offset = 0.0
        self.saturated = False

    def update(self, reference: float, measured: float, dt: float, speed: float) -> float:
        """Return the offset b (rad) after one sample ``dt`` s after the previous one."""
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ValueError(f'dt must be finite and >= 0, got {dt}')
        g = self.gains
        if speed < MIN_TURNING_SPEED_M_S:
            self.reset()
            return 0.0
        plant = g.turn_gain * speed
        error = reference - measured
        raw = (reference + g.kp * error + self.integral) / plant
        limit = g.max_offset_rad
        # Integrate unless the output is saturated and the error would push it further.
        pushes_out = (raw >= limit and error / plant > 0.0) or \
                     (raw <= -limit and error / plant < 0.0)
        if not pushes_out:
            self.integral = min(g.integral_limit, max(-g.integral_limit,
                                                      self.integral + g.ki * error * dt))
        raw = (reference + g.kp * error + self.integral) / plant
        self.offset = min(limit, max(-limit, raw))
        self.saturated = abs(raw) > limit
        return self.offset


MIN_TURN_SPREAD = 0.005  # m/s x rad: U b must vary this much (a run with turns)


def identify_turn_gain(speed: np.ndarray, offset: np.ndarray, yaw_rate: np.ndarray
                       ) -> tuple[float, float]:
    """
    Return (k, d) of r = k U b + d fitted by least squares to samples of U, b and r.

    ``speed`` U (m/s), ``offset`` b (rad) and ``yaw_rate`` r (rad/s) are arrays of one length.
    Raises ValueError when U b hardly varies (a straight run cannot tell k from d).
    """
    x = np.asarray(speed, dtype=float) * np.asarray(offset, dtype=float)
    r = np.asarray(yaw_rate, dtype=float)
    keep = np.isfinite(x) & np.isfinite(r)
    x, r = x[keep], r[keep]
    if len(x) < 3 or float(np.std(x)) < MIN_TURN_SPREAD:
        raise ValueError(f'U b varies by {float(np.std(x)) if len(x) else 0.0:.4g} m/s rad over '
                         f'{len(x)} samples: the run must turn to identify the turn gain')
    design = np.column_stack([x, np.ones_like(x)])
    (gain, bias), *_ = np.linalg.lstsq(design, r, rcond=None)
    return float(gain), float(bias)


def steady_means(t: np.ndarray, speed: np.ndarray, offset: np.ndarray, yaw_rate: np.ndarray,
                 window_s: float = 1.0, max_offset_change: float = 0.02
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the means of U, b and r over consecutive ``window_s`` windows where b held still.

    A window counts when b moved less than ``max_offset_change`` rad in it and in the window
    before it (the yaw rate lags b by the CPG's and the body's time constants).
    """
    t = np.asarray(t, dtype=float)
    edges = np.arange(t[0], t[-1], window_s) if len(t) else np.array([])
    # (means of U, b, r; how far b moved) per window, None for an empty window
    windows: list[tuple[tuple[float, float, float], float] | None] = []
    for start in edges:
        inside = (t >= start) & (t < start + window_s)
        if not inside.any():
            windows.append(None)
            continue
        b = offset[inside]
        windows.append(((float(speed[inside].mean()), float(b.mean()),
                         float(yaw_rate[inside].mean())), float(b.max() - b.min())))
    keep = []
    for before, now in zip(windows, windows[1:]):
        if before is None or now is None:
            continue
        steady = max(before[1], now[1]) < max_offset_change and \
            abs(now[0][1] - before[0][1]) < max_offset_change
        if steady:
            keep.append(now[0])
    if not keep:
        return np.array([]), np.array([]), np.array([])
    u, b, r = (np.array(column) for column in zip(*keep))
    return u, b, r
