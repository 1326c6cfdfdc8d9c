# SPDX-License-Identifier: Apache-2.0
"""
Eq 1 for the fish's two oscillators started from rest, solved in closed form.

From rest (all phases, amplitudes and rates 0, b = 0) with one alpha for both oscillators, the
amplitude law of eq 1 is critically damped and the same for both: r_i(t) = R_i g(t) with

    g(t) = 1 - (1 + a t) exp(-a t),     a = alpha / 2.

Every coupling term of eq 1 carries one r_j, so in the warped time tau(t) = int_0^t g the phase
difference Delta = xi_2 - xi_1 obeys an autonomous equation (``steady_state``'s A, B, C, psi):

    dDelta / dtau = A sin(Delta) + B cos(Delta) = C sin(Delta + psi).

With u = Delta + psi this separates: tan(u / 2) = tan(psi / 2) exp(C tau) (Delta(0) = 0), and

    xi_1(t) = 2 pi v t + R_2 w12 int_0^tau sin(u - c) dtau',        c = psi + phi12,
    int_0^tau sin(u - c) = ((u - u0) cos(c) - sin(c) (ln|sin u| - ln|sin u0|)) / C,

with ln|sin u| = ln 2 + ln|X| - ln(1 + X^2), X = tan(u / 2), evaluated from ln|X| (linear in
tau) so that it stays exact however long the network has been locked. Then xi_2 = xi_1 + Delta
and Theta_i = r_i cos(xi_i). This is the trajectory a perfect integrator of eq 1 would produce;
the tests compare it with scipy's DOP853. It broadcasts over particles and over time, so the
paper-literal loss needs no time stepping.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

# Below this coupling strength C (rad/s) Delta stays at 0 to first order over any window of
# interest (C tau < 1e-7 rad over 100 s) and the closed form's divisions by C lose precision.
_WEAK_COUPLING = 1e-9


def amplitude_envelope(t: ArrayLike, alpha: float) -> np.ndarray:
    """Return g(t) = r_i(t) / R_i of eq 1's amplitude law from rest (dimensionless)."""
    a = 0.5 * float(alpha)
    t = np.asarray(t, dtype=float)
    return 1.0 - (1.0 + a * t) * np.exp(-a * t)


def envelope_time(t: ArrayLike, alpha: float) -> np.ndarray:
    """Return tau(t) = int_0^t g (s): the time the coupling has acted at full amplitude."""
    a = 0.5 * float(alpha)
    t = np.asarray(t, dtype=float)
    decay = np.exp(-a * t)
    tau: np.ndarray = t - 2.0 * (1.0 - decay) / a + t * decay
    return tau


def phases_from_rest(t: ArrayLike, frequency_hz: ArrayLike, r1: ArrayLike, r2: ArrayLike,
                     w12: ArrayLike, w21: ArrayLike, phi12: ArrayLike, phi21: ArrayLike,
                     alpha: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the phases (xi_1, xi_2) (rad) of eq 1 at times ``t`` (s) after a start from rest.

    The parameters (Hz, rad, 1/s, rad) broadcast against ``t``: pass per-particle arrays of
    shape (P, 1) and times (T,) for (P, T) results.
    """
    t = np.asarray(t, dtype=float)
    r1, r2, w12, w21, phi12, phi21 = (np.asarray(v, dtype=float)
                                      for v in (r1, r2, w12, w21, phi12, phi21))
    a = -r1 * w21 * np.cos(phi21) - r2 * w12 * np.cos(phi12)
    b = -r1 * w21 * np.sin(phi21) + r2 * w12 * np.sin(phi12)
    strength = np.hypot(a, b)
    psi = np.arctan2(b, a)
    tau = envelope_time(t, alpha)
    c = psi + phi12
    weak = strength < _WEAK_COUPLING
    safe = np.where(weak, 1.0, strength)
    with np.errstate(divide='ignore', over='ignore', invalid='ignore'):
        log_x0 = np.log(np.abs(np.tan(0.5 * psi)))
        log_x = log_x0 + safe * tau
        u = 2.0 * np.arctan(np.copysign(np.exp(log_x), psi))
        u = np.where(np.isnan(u), psi, u)  # psi = 0 exactly: the unstable equilibrium holds
        log_ratio = np.where(np.isfinite(log_x0),
                             np.logaddexp(0.0, 2.0 * log_x) - np.logaddexp(0.0, 2.0 * log_x0),
                             0.0)
    integral = ((u - psi) * np.cos(c) - np.sin(c) * (safe * tau - log_ratio)) / safe
    u = np.where(weak, psi, u)
    integral = np.where(weak, tau * np.sin(psi - c), integral)
    xi1 = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float) * t + r2 * w12 * integral
    return xi1, xi1 + (u - psi)


def outputs_from_rest(t: ArrayLike, frequency_hz: ArrayLike, r1: ArrayLike, r2: ArrayLike,
                      w12: ArrayLike, w21: ArrayLike, phi12: ArrayLike, phi21: ArrayLike,
                      alpha: float = 20.0) -> np.ndarray:
    """
    Return the outputs Theta_i = r_i(t) cos(xi_i(t)) (rad) of eq 1 from rest, (..., 2).

    Offsets b_i are 0 (paper section 4.1, straight motion). Arguments as ``phases_from_rest``.
    """
    xi1, xi2 = phases_from_rest(t, frequency_hz, r1, r2, w12, w21, phi12, phi21, alpha)
    g = amplitude_envelope(t, alpha)
    return np.stack([np.asarray(r1) * g * np.cos(xi1), np.asarray(r2) * g * np.cos(xi2)],
                    axis=-1)
