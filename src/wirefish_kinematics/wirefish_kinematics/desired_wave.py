# SPDX-License-Identifier: Apache-2.0
"""
Lighthill's desired travelling body wave (paper eq 23) and the expected swing angles (5.2).

    y_body(q, t) = (c1 q + c2 q^2) sin(k q + WAVE_TIME_SIGN 2 pi f t)

The paper prints +omega t, a wave running towards the head. The project uses the tail-ward wave
sin(k q - omega t) (``WAVE_TIME_SIGN = -1``): it is the one that produces thrust, and Table 1's
own parameters only fit that one (wirefish_cpg README). Change the sign here and nowhere else;
every function takes ``time_sign`` to evaluate the other reading explicitly.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from wirefish_kinematics.geometry import FishGeometry

WAVE_TIME_SIGN = -1.0


def desired_lateral_position(q: ArrayLike, t: ArrayLike, c1: float, c2: float, k: float,
                             frequency_hz: float, time_sign: float = WAVE_TIME_SIGN
                             ) -> np.ndarray:
    """
    Return y_body(q, t) (m) of eq 23; ``q`` (m) and ``t`` (s) broadcast together.

    c1 (m/m) and c2 (1/m) shape the envelope, k (rad/m) is the wave number, frequency_hz the
    wave frequency omega / (2 pi). For a (T, S) grid pass ``t[:, None]`` and ``q[None, :]``.
    """
    q = np.asarray(q, dtype=float)
    t = np.asarray(t, dtype=float)
    phase = k * q + time_sign * 2.0 * math.pi * frequency_hz * t
    y: np.ndarray = (c1 * q + c2 * q * q) * np.sin(phase)
    return y


def desired_swing_angles(t: ArrayLike, c1: float, c2: float, k: float, frequency_hz: float,
                         geometry: FishGeometry, time_sign: float = WAVE_TIME_SIGN
                         ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the expected swing angles (theta-bar1, theta-bar2) (rad) of section 5.2 at ``t``.

    eq 23 gives the wave point at axial position q_i as (q_i, y_body(q_i, t)), so
    theta-bar_i = atan2(y_body(q_i, t), q_i) at the link ends q1 = l1, q2 = l1 + l2.
    """
    t = np.asarray(t, dtype=float)
    angles = []
    for station in geometry.link_end_stations:
        y = desired_lateral_position(station, t, c1, c2, k, frequency_hz, time_sign)
        angles.append(np.arctan2(y, station))
    return angles[0], angles[1]


def wave_time_at_phase(phase_at_q1: ArrayLike, q1: float, k: float, frequency_hz: float,
                       time_sign: float = WAVE_TIME_SIGN) -> np.ndarray:
    """
    Return the wave time tau (s) at which y_body(q1, tau) is proportional to cos(phase_at_q1).

    The CPG's absolute phase is arbitrary, so the desired wave is shown at the tail's phase:
    if y(q1, t) ~ cos(p(t)), the overlay y_body(q, tau(t)) peaks at q1 with it (solving
    k q1 + s omega tau - pi/2 = s p for the sign s, so that tau grows with p).
    """
    omega = 2.0 * math.pi * frequency_hz
    phase = np.asarray(phase_at_q1, dtype=float)
    return (phase + time_sign * (0.5 * math.pi - k * q1)) / omega


def desired_wave_at_phase(q: ArrayLike, phase_at_q1: float, q1: float, c1: float, c2: float,
                          k: float, frequency_hz: float, time_sign: float = WAVE_TIME_SIGN
                          ) -> np.ndarray:
    """
    Return y_body(q, tau) (m) of eq 23 shown at the tail's phase: it peaks at q1 with it.

    tau is ``wave_time_at_phase``'s; where the envelope c1 q1 + c2 q1^2 is negative the wave
    is shifted by half a period, so that y_body(q1) = |envelope(q1)| cos(phase_at_q1) always
    has the sign of the tail's own y(q1).
    """
    if c1 * q1 + c2 * q1 * q1 < 0.0:
        phase_at_q1 += math.pi
    tau = wave_time_at_phase(phase_at_q1, q1, k, frequency_hz, time_sign)
    return desired_lateral_position(q, tau, c1, c2, k, frequency_hz, time_sign)
