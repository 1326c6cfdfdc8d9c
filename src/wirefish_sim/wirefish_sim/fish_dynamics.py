# SPDX-License-Identifier: Apache-2.0
"""
Surge and yaw dynamics of the virtual fish (pure functions; SI units).

Surge: Lighthill's time-resolved reactive thrust (``wirefish_kinematics.lighthill``) against the
drag of eq 17, with the body's mass, its longitudinal added mass and the lateral momentum's
share K2 as the inertia::

    (M + K2) dU/dt = T_tip(t) - dK1/dt - U dK2/dt - F_D(U),      M = m + m_added,

where T_tip is the eq 16 integrand at the tail tip, K1 = int m dy/dt dy/dq dq and
K2 = int m (dy/dq)^2 dq along the tail. The period means of dK1/dt and dK2/dt vanish, so the
mean thrust is eq 16's and the steady mean speed is eq 18's (within the ripple's second-order
effect: the test checks 1 % with ideal servos). Nothing is chosen: the speed ripple comes from
the thrust's variation within a beat and the time constant from the inertia over the
damping, tau = (M + <K2>) / (dF_D/dU + rho A(L_T) U <(dy/dq)^2>) (``surge_time_constant``),
about 0.07 s at 0.39 m/s with the paper's effective drag (C_D rho S_c = 140 kg/m).

Yaw: a model assumption (the paper has none): the yaw rate relaxes with ``time_constant`` to
-gain U y_tip / L (gain 20 by default), where y_tip is the tail tip's lateral offset (+ = right
in C0). A tail held to the right turns the fish right (negative yaw about z up); the beating
part of y_tip averages out and leaves the head's small yaw oscillation.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

GRAVITY = 9.80665  # m/s^2, standard gravity
# A value of one fish, or an array of a school's (one per fish: ``virtual_fish.swim``).
Value = float | np.ndarray
Angle = TypeVar('Angle', float, np.ndarray)


def surge_acceleration(tip_thrust: Value, k1_rate: Value, k2: Value, k2_rate: Value,
                       speed: Value, drag: Value, total_mass: float) -> Value:
    """
    Return dU/dt (m/s^2) of the surge equation above.

    ``tip_thrust`` T_tip (N), ``k1_rate`` dK1/dt (N), ``k2`` (kg) and ``k2_rate`` (kg/s) of
    the tail's lateral momentum, ``speed`` U (m/s), ``drag`` F_D (N), ``total_mass`` M (kg).
    """
    return (tip_thrust - k1_rate - speed * k2_rate - drag) / (total_mass + k2)


def surge_time_constant(total_mass: float, mean_k2: float, speed: float,
                        mean_square_slope: float, drag_coefficient: float,
                        water_density: float, wetted_area: float,
                        tip_cross_section_area: float) -> float:
    """
    Return the linearised surge time constant (s) about a steady mean ``speed`` (m/s).

    Damping d(F_D - <T_tip>)/dU = rho (C_D S_c + A(L_T) <(dy/dq)^2>) U (eqs 16-17); inertia
    M + <K2>.
    """
    damping = water_density * (drag_coefficient * wetted_area
                               + tip_cross_section_area * mean_square_slope) * speed
    return (total_mass + mean_k2) / damping


def yaw_acceleration(yaw_rate: Value, tail_tip_offset: Value, speed: Value, gain: float,
                     time_constant: float, body_length: float) -> Value:
    """Return d(yaw rate)/dt (rad/s^2) of the yaw model above (a model assumption)."""
    target = -gain * speed * tail_tip_offset / body_length
    return (target - yaw_rate) / time_constant


def wrap_angle(angle: Angle) -> Angle:
    """Return ``angle`` wrapped into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
