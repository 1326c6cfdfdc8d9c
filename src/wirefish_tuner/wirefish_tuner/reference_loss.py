# SPDX-License-Identifier: Apache-2.0
"""
The loss of eqs 24-25 computed the obvious way: integrate eq 1 for one particle at a time.

This is what the tuner does NOT do (it uses the closed-form steady state, ``wave_loss``). It is
kept as the honest baseline of the retune benchmark and as an independent check of the closed
form in the tests: plain RK4 on Python floats from rest (v = the wave's frequency, as printed in
the paper), then the last full cycle of oscillator 1 is resampled on the same grid and with the
same phase reference as ``wave_loss`` (oscillator 1 aligned with the wave at q1). Slow-locking
particles may not have settled at ``settle_s``; that inaccuracy belongs to the method.
"""

from __future__ import annotations

import math

import numpy as np
from wirefish_tuner.wave_loss import (admissible_frequency, FREQUENCY_PENALTY, oscillator1_phase,
                                      WaveFitProblem, waveform_loss, waveform_swing_rmse_deg)


def _derivative(state: list[float], v: float, r_target: tuple[float, float], w12: float,
                w21: float, phi12: float, phi21: float, alpha: float) -> list[float]:
    """Return d(state)/dt of eq 1 for two oscillators, state [xi1, xi2, r1, r2, dr1, dr2]."""
    xi1, xi2, r1, r2, dr1, dr2 = state
    return [2.0 * math.pi * v + r2 * w12 * math.sin(xi2 - xi1 - phi12),
            2.0 * math.pi * v + r1 * w21 * math.sin(xi1 - xi2 - phi21),
            dr1, dr2,
            alpha * (0.25 * alpha * (r_target[0] - r1) - dr1),
            alpha * (0.25 * alpha * (r_target[1] - r2) - dr2)]


def simulated_cycle(position: np.ndarray, problem: WaveFitProblem, alpha: float = 20.0,
                    settle_s: float = 3.0, step_s: float = 2e-3
                    ) -> tuple[np.ndarray, float]:
    """
    Integrate eq 1 for one particle (6,) and return its last cycle on the loss grid.

    Returns (angles (N, 2) rad on ``problem.times()`` with oscillator 1 phase-referenced as in
    ``wave_loss``, the intrinsic frequency v (Hz) that would lock the network to the wave;
    NaN, and zero angles, when oscillator 1 did not complete a cycle within 10 periods).
    """
    w12, w21, phi12, phi21, r1, r2 = (float(v) for v in position)
    v = problem.wave.frequency_hz
    args = (v, (r1, r2), w12, w21, phi12, phi21, alpha)
    state = [0.0] * 6
    h = step_s
    settle_steps = int(round(settle_s / h))
    # Record until oscillator 1 has turned a full cycle (either way round), at most 10 wave
    # periods: a network locked near zero frequency has no usable cycle and is penalised.
    limit_steps = settle_steps + int(round(10.0 / (v * h)))
    phases, outputs = [], []
    for n in range(1, limit_steps + 1):
        k1 = _derivative(state, *args)
        k2 = _derivative([s + 0.5 * h * k for s, k in zip(state, k1)], *args)
        k3 = _derivative([s + 0.5 * h * k for s, k in zip(state, k2)], *args)
        k4 = _derivative([s + h * k for s, k in zip(state, k3)], *args)
        state = [s + h / 6.0 * (a + 2.0 * b + 2.0 * c + d)
                 for s, a, b, c, d in zip(state, k1, k2, k3, k4)]
        if n >= settle_steps:
            phases.append(state[0])
            outputs.append((state[2] * math.cos(state[0]), state[3] * math.cos(state[1])))
            if abs(state[0] - phases[0]) > 2.0 * math.pi + 2.0 * abs(k1[0]) * h:
                break
    phase_track, output_track = np.array(phases), np.array(outputs)
    omega_measured = (phase_track[-1] - phase_track[0]) / (h * (len(phase_track) - 1))
    omega = 2.0 * np.pi * v
    if abs(phase_track[-1] - phase_track[0]) < 2.0 * np.pi:
        return np.zeros((problem.samples_per_period, 2)), math.nan
    if phase_track[-1] < phase_track[0]:  # turning backwards: same waveform as a function of phase
        phase_track, output_track = phase_track[::-1], output_track[::-1]
    # Oscillator 1's phase on the loss grid; the outputs follow by interpolation in phase.
    grid = oscillator1_phase(problem) + (np.pi if r1 < 0.0 else 0.0) + omega * problem.times()
    grid = phase_track[0] + np.mod(grid - phase_track[0], 2.0 * np.pi)
    angles = np.stack([np.interp(grid, phase_track, output_track[:, i]) for i in range(2)],
                      axis=-1)
    intrinsic = v - (omega_measured - omega) / (2.0 * np.pi)
    return angles, float(intrinsic)


def simulated_body_wave_loss(position: np.ndarray, problem: WaveFitProblem, **kwargs: float
                             ) -> float:
    """Return the loss of eqs 24-25 (m*s) of one particle (6,) by integrating eq 1."""
    angles, intrinsic = simulated_cycle(position, problem, **kwargs)
    loss = float(waveform_loss(angles[None], problem)[0])
    if not (math.isfinite(intrinsic) and admissible_frequency(np.array(intrinsic), problem)):
        loss += FREQUENCY_PENALTY
    return loss


def simulated_swing_rmse_deg(position: np.ndarray, problem: WaveFitProblem, **kwargs: float
                             ) -> np.ndarray:
    """Return the theta_1, theta_2 RMSE (2,) degrees of one particle by integrating eq 1."""
    angles, _ = simulated_cycle(position, problem, **kwargs)
    rmse: np.ndarray = waveform_swing_rmse_deg(angles[None], problem)[0]
    return rmse
