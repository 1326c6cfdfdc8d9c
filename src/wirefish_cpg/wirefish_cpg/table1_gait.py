# SPDX-License-Identifier: Apache-2.0
"""
Table 1's gait at any tail-beat frequency and tail-tip amplitude (paper sections 5.3-5.4).

The paper drives its fish with Table 1's CPG parameters at other frequencies and at stated
tail-tip amplitudes. Here that means: both amplitudes R_i scaled by one factor (which leaves the
locked phase difference unchanged), and the intrinsic frequency v of eq 1 chosen so that the
coupled network locks at the wanted tail-beat frequency (coupling shifts it: v = 1 Hz locks at
1.0055 Hz). Used by the drag calibration, the speed sweep and the virtual fish's Fig 11.
"""

from __future__ import annotations

from dataclasses import replace
import math

import numpy as np
from scipy.optimize import brentq
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import (intrinsic_frequency_for, stable_phase_difference,
                                       steady_state_phases, steady_state_servo_angles)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (estimate_speed, SpeedEstimate,
                                           tail_tip_lateral_positions)

TABLE1 = CpgParameters()  # Table 1: w12, w21, phi12, phi21, R1, R2; alpha = 20, b = 0
# The grid of the paper's speed experiments (section 5.4, Figs 9-10): f = 1.0 ... 3.0 Hz in
# steps of 0.2 Hz at tail-tip half amplitudes {4, 4.5, 6.5, 8, 9} cm. The paper stops at 3 Hz
# because its servos could not go faster at these amplitudes.
PAPER_GRID_FREQUENCIES_HZ = tuple(round(1.0 + 0.2 * k, 1) for k in range(11))
PAPER_GRID_AMPLITUDES_M = (0.04, 0.045, 0.065, 0.08, 0.09)
SAMPLES_PER_PERIOD = 512
AMPLITUDE_SAMPLES = 4096  # dense sampling for the tip's half amplitude (peaks between samples)


def table1_locked_at(frequency_hz: float, amplitude_scale: float = 1.0,
                     base: CpgParameters = TABLE1) -> CpgParameters:
    """Return ``base`` with R_i scaled and v chosen so that the network locks at frequency_hz."""
    r1, r2 = (amplitude_scale * r for r in base.amplitude)
    delta = stable_phase_difference(r1, r2, base.w12, base.w21, base.phi12, base.phi21)
    v = float(intrinsic_frequency_for(frequency_hz, r2, base.w12, base.phi12, delta))
    return replace(base, frequency_hz=v, amplitude=(r1, r2))


def one_locked_period(params: CpgParameters,
                      samples: int = SAMPLES_PER_PERIOD) -> tuple[np.ndarray, np.ndarray, float]:
    """Return (angles (N, 2) rad, rates (N, 2) rad/s, dt s) over one locked period."""
    _, omega = steady_state_phases(params)
    dt = 2.0 * math.pi / omega / samples
    angles, rates = steady_state_servo_angles(params, np.arange(samples) * dt)
    return angles, rates, dt


def tip_half_amplitude(params: CpgParameters, geometry: FishGeometry) -> float:
    """Return the tail tip's half peak-to-peak lateral excursion (m) in the steady state."""
    angles, _, _ = one_locked_period(params, AMPLITUDE_SAMPLES)
    return 0.5 * float(np.ptp(tail_tip_lateral_positions(angles, geometry)))


def locked_speed_estimate(params: CpgParameters, geometry: FishGeometry) -> SpeedEstimate:
    """Return eqs 16-22 on one locked period of ``params`` (servos that follow exactly)."""
    angles, rates, dt = one_locked_period(params)
    return estimate_speed(angles, rates, dt, geometry)


def amplitude_scale_for(tip_amplitude: float, frequency_hz: float,
                        geometry: FishGeometry) -> float:
    """
    Return the factor on Table 1's R_i that gives the tail tip this half amplitude (m).

    Raises ``ValueError`` when the amplitude is out of reach with |R_i| <= pi/2 on ``geometry``.
    """
    limit = 0.999 * (math.pi / 2) / max(abs(r) for r in TABLE1.amplitude)  # |R_i| <= pi/2

    def miss(scale: float) -> float:
        return tip_half_amplitude(table1_locked_at(frequency_hz, scale), geometry) - tip_amplitude

    if miss(limit) < 0.0:
        raise ValueError(f'a tail-tip half amplitude of {100 * tip_amplitude:g} cm is out of '
                         f'reach with |R_i| <= pi/2 on this geometry (at most '
                         f'{100 * (miss(limit) + tip_amplitude):.2f} cm)')
    return float(brentq(miss, 1e-6, limit, xtol=1e-12))


def table1_at_tip_amplitude(tip_amplitude: float, frequency_hz: float,
                            geometry: FishGeometry) -> CpgParameters:
    """Return Table 1's gait scaled to this tail-tip half amplitude (m), locked at f (Hz)."""
    return table1_locked_at(frequency_hz,
                            amplitude_scale_for(tip_amplitude, frequency_hz, geometry))
