# SPDX-License-Identifier: Apache-2.0
"""
Closed-form steady state of the two-oscillator network of eq 1.

Once r_i = R_i and b_i = B_i, only the phase difference Delta = xi_2 - xi_1 still moves::

    dDelta/dt = R_1 w21 sin(-Delta - phi21) - R_2 w12 sin(Delta - phi12)      (from eq 1)
              = A sin(Delta) + B cos(Delta) = C sin(Delta + psi)

with A = -R_1 w21 cos(phi21) - R_2 w12 cos(phi12), B = -R_1 w21 sin(phi21) + R_2 w12 sin(phi12),
C = hypot(A, B), psi = atan2(B, A). Its zeros are Delta = -psi + n pi; the stable one (negative
slope C cos(Delta + psi) = -C) is Delta* = pi - psi. Both oscillators then turn at the common
angular frequency Omega = 2 pi v + R_2 w12 sin(Delta* - phi12), which differs from 2 pi v
whenever the coupling term does not vanish. With C = 0 (no effective coupling) every Delta is
neutral; the network started at rest keeps Delta = 0, so that is returned.

All functions broadcast over leading particle dimensions, so the tuner evaluates a whole swarm
with a handful of array operations instead of integrating eq 1 per particle.
"""

from __future__ import annotations

import numpy as np

from wirefish_cpg.oscillator import CpgParameters

Real = float | np.ndarray  # a number or an array of them: every function here broadcasts


def phase_difference_rate(delta: Real, r1: Real, r2: Real,
                          w12: Real, w21: Real, phi12: Real,
                          phi21: Real) -> np.ndarray:
    """Return dDelta/dt (rad/s) of Delta = xi_2 - xi_1 at amplitudes r1, r2 (from eq 1)."""
    return r1 * w21 * np.sin(-delta - phi21) - r2 * w12 * np.sin(delta - phi12)


def stable_phase_difference(r1: Real, r2: Real, w12: Real,
                            w21: Real, phi12: Real,
                            phi21: Real) -> np.ndarray:
    """
    Return the stable root Delta* in (-pi, pi] of the phase-difference equation (from eq 1).

    Arguments broadcast together (rad, 1/s); the result has their broadcast shape. Where the
    other root is Delta = 0 (B = 0, A > 0), a network started exactly in phase with bit-equal
    oscillators can sit on that unstable equilibrium forever; any perturbation (and every
    real start-up) leaves it for Delta*, which is what is returned. NaN in, NaN out.
    """
    a = -r1 * w21 * np.cos(phi21) - r2 * w12 * np.cos(phi12)
    b = -r1 * w21 * np.sin(phi21) + r2 * w12 * np.sin(phi12)
    coupled = ~(np.hypot(a, b) <= 1e-12)  # NaN counts as coupled, so NaN comes out
    delta = np.pi - np.arctan2(b, a)
    delta = np.pi - np.mod(np.pi - delta, 2.0 * np.pi)  # wrap into (-pi, pi]
    return np.where(coupled, delta, 0.0)


def locked_angular_frequency(frequency_hz: Real, r2: Real, w12: Real,
                             phi12: Real, delta: Real) -> np.ndarray:
    """Return the common angular frequency Omega (rad/s) at phase difference ``delta`` (eq 1)."""
    return 2.0 * np.pi * frequency_hz + r2 * w12 * np.sin(delta - phi12)


def intrinsic_frequency_for(target_hz: Real, r2: Real, w12: Real,
                            phi12: Real, delta: Real) -> np.ndarray:
    """
    Return the intrinsic frequency v (Hz) that makes the locked network turn at ``target_hz``.

    Inverts ``locked_angular_frequency``: Delta* does not depend on v, so this is exact.
    """
    return target_hz - r2 * w12 * np.sin(delta - phi12) / (2.0 * np.pi)


def steady_state_phases(params: CpgParameters) -> tuple[float, float]:
    """Return (Delta* rad, Omega rad/s) of the locked network of ``params``."""
    r1, r2 = params.amplitude
    delta = float(stable_phase_difference(r1, r2, params.w12, params.w21, params.phi12,
                                          params.phi21))
    omega = float(locked_angular_frequency(params.frequency_hz, r2, params.w12, params.phi12,
                                           delta))
    return delta, omega


def steady_state_servo_angles(params: CpgParameters, t: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the locked outputs of eq 1: (angles (T, 2) rad, rates (T, 2) rad/s) at ``t`` (T,) s.

    Theta_1 = R_1 cos(Omega t) + B_1 and Theta_2 = R_2 cos(Omega t + Delta*) + B_2: the absolute
    phase after start-up is arbitrary, so oscillator 1's phase is taken as 0 at t = 0.
    """
    t = np.asarray(t, dtype=float)
    delta, omega = steady_state_phases(params)
    phases = omega * t[:, None] + np.array([0.0, delta])
    amplitude = np.asarray(params.amplitude)
    angles = amplitude * np.cos(phases) + np.asarray(params.offset)
    rates = -amplitude * omega * np.sin(phases)
    return angles, rates
