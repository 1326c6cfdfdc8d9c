# SPDX-License-Identifier: Apache-2.0
"""
Mechanical coupling of the two wire pairs (paper eqs 2-4 and 21-22).

Reel i turns by phi_Di (= the CPG output Theta_i, the servo angle) and shortens wire pair i by
R_Di phi_Di. Pair 1 ends at plate III and bends link L1 only; pair 2 ends at plate V and bends
both links (eq 2). All functions broadcast over any array shape.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wirefish_kinematics.geometry import FishGeometry


def bend_angles(servo_1: ArrayLike, servo_2: ArrayLike, geometry: FishGeometry
                ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the bend (central) angles (beta1, beta2) of links L1, L2 (rad), eqs 3-4.

    beta1 = R_D1 phi_D1 / r1 and beta2 = R_D2 phi_D2 / r2 - beta1, from servo angles phi_D1,
    phi_D2 (rad, broadcast together). Positive bends the tail to the right (+y of C0).
    """
    beta1 = geometry.rd1 * np.asarray(servo_1, dtype=float) / geometry.r1
    beta2 = geometry.rd2 * np.asarray(servo_2, dtype=float) / geometry.r2 - beta1
    return beta1, beta2


def bend_rates(servo_rate_1: ArrayLike, servo_rate_2: ArrayLike, geometry: FishGeometry
               ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the bend rates (beta1_dot, beta2_dot) (rad/s) from servo rates (rad/s), eqs 21-22.

    The coupling is linear, so the rates follow the angles' map (eqs 3-4 differentiated).
    """
    return bend_angles(servo_rate_1, servo_rate_2, geometry)


def servo_angles_for(beta1: ArrayLike, beta2: ArrayLike, geometry: FishGeometry
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Return the servo angles (phi_D1, phi_D2) (rad) that bend the links by beta1, beta2."""
    beta1 = np.asarray(beta1, dtype=float)
    servo_1 = geometry.r1 * beta1 / geometry.rd1
    servo_2 = geometry.r2 * (beta1 + np.asarray(beta2, dtype=float)) / geometry.rd2
    return servo_1, servo_2
