# SPDX-License-Identifier: Apache-2.0
"""
The tail's shape at one pair of servo angles: what one body_wave message shows.

Servo angles -> bend angles (eqs 2-4) -> positions along the tail (eqs 7-15), the swing angles
of section 5.2 and the link ends O1, O2, in frame C0 (``tail_base``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wirefish_kinematics.body_wave import body_positions
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import bend_angles


@dataclass(frozen=True)
class TailShape:
    """
    The tail at one instant: stations q (S,) m from plate I to the tip, their x, y (S,) m.

    ``beta1``, ``beta2`` the bend angles and ``theta1``, ``theta2`` the swing angles (rad);
    ``ends_x``, ``ends_y`` (2,) m the link ends O1 (q = l1) and O2 (q = l1 + l2).
    """

    stations: np.ndarray
    x: np.ndarray
    y: np.ndarray
    beta1: float
    beta2: float
    theta1: float
    theta2: float
    ends_x: np.ndarray
    ends_y: np.ndarray


def tail_shape(servo_angles: tuple[float, float], geometry: FishGeometry, station_count: int
               ) -> TailShape:
    """Return the tail's shape at ``servo_angles`` (rad) on ``station_count`` (>= 2) stations."""
    beta1, beta2 = (float(b) for b in bend_angles(servo_angles[0], servo_angles[1], geometry))
    stations = np.linspace(0.0, geometry.tail_length, station_count)
    # The stations and the link ends in one evaluation of eqs 7-15 (three, with the swing
    # angles' own, were two thirds of the node's 50 Hz tick): the swing angles of section 5.2
    # are the directions of the link ends, as in ``swing_angles``.
    x, y = body_positions(np.concatenate([stations, geometry.link_end_stations]), beta1, beta2,
                          geometry)
    ends_x, ends_y = x[station_count:], y[station_count:]
    theta1, theta2 = np.arctan2(ends_y, ends_x)
    return TailShape(stations, x[:station_count], y[:station_count], beta1, beta2,
                     float(theta1), float(theta2), ends_x, ends_y)
