# SPDX-License-Identifier: Apache-2.0
"""
The fish's frames and where they sit (pure: no rclpy), REP-103 and REP-105.

The tree: ``odom`` -> ``base_link`` -> ``imu_link`` (static), ``base_link`` -> ``tail_base``
(static) -> ``tail_plate_ii``, ``tail_plate_iii``, ``caudal_fin`` (moving with the tail).

- ``base_link``: the head's tip (the nose), x forward, y left, z up (REP-103). The fish's pose
  in ``odom`` is given for this point.
- ``tail_base``: the paper's C0 (section 3.1): origin at oval plate I, x along the initial body
  axis towards the tail tip, so rotated by pi about z; plate I sits ``body_length - L_T``
  behind the nose (the tail is the last L_T = l1 + l2 + l3 of the body).
- ``imu_link``: the IMU board, axes aligned with ``base_link`` (REP-145; the board reports
  FLU), at ``imu_x``, ``imu_y``, ``imu_z`` in ``base_link`` (an estimate: the paper does not
  place it).
- ``tail_plate_ii``: oval plate II, on L1; the paper does not place it: assumed midway along
  L1 (q = l1 / 2), an estimate. ``tail_plate_iii``: plate III, the paper's C1 (q = l1).
  ``caudal_fin``: plate V, the paper's C2 (q = l1 + l2), where the rigid fin L3 starts; x
  along the fin towards its tip. Each tail frame's x is tangent to the body axis (eqs 7-15).
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import math

import numpy as np
from wirefish_kinematics.body_wave import body_positions, tangent_angles
from wirefish_kinematics.geometry import FishGeometry


class Frame(enum.StrEnum):
    """The frame ids of one fish (before its ``frame_prefix``)."""

    ODOM = 'odom'
    BASE_LINK = 'base_link'
    IMU_LINK = 'imu_link'
    TAIL_BASE = 'tail_base'
    PLATE_II = 'tail_plate_ii'
    PLATE_III = 'tail_plate_iii'
    FIN = 'caudal_fin'


class OdomSource(enum.StrEnum):
    """Where ``odom`` -> ``base_link`` comes from (the ``odom_source`` parameter)."""

    AUTO = 'auto'  # ground truth once sim/ground_truth is heard, dead reckoning until then
    GROUND_TRUTH = 'ground_truth'  # the virtual fish's sim/ground_truth, as published
    DEAD_RECKONING = 'dead_reckoning'  # the real fish: IMU yaw and the speed estimate


@dataclass(frozen=True)
class PlanarPose:
    """A pose in the plane of its parent: x, y (m), z (m, along the parent's z), yaw (rad)."""

    x: float
    y: float
    yaw: float
    z: float = 0.0


# Plate II's station as a fraction of l1 (estimate, see the module docstring).
PLATE_II_FRACTION = 0.5


def tail_base_in_base_link(geometry: FishGeometry) -> PlanarPose:
    """Return C0 (plate I) in base_link: body_length - L_T behind the nose, turned by pi."""
    return PlanarPose(x=-(geometry.body_length - geometry.tail_length), y=0.0, yaw=math.pi)


def tail_frame_stations(geometry: FishGeometry) -> dict[Frame, float]:
    """Return the arc length q (m) from plate I of each moving tail frame."""
    return {Frame.PLATE_II: PLATE_II_FRACTION * geometry.l1,
            Frame.PLATE_III: geometry.l1,
            Frame.FIN: geometry.l1 + geometry.l2}


def tail_frames(beta1: float, beta2: float, geometry: FishGeometry) -> dict[Frame, PlanarPose]:
    """
    Return the moving tail frames in C0 for bend angles ``beta1``, ``beta2`` (rad), eqs 7-15.

    Each frame's origin is the body axis at its station (``body_positions``) and its x the
    tangent there (``tangent_angles``: phi1 + phi2).
    """
    stations = tail_frame_stations(geometry)
    q = np.array(list(stations.values()))
    x, y = body_positions(q, beta1, beta2, geometry)
    yaw = tangent_angles(q, beta1, beta2, geometry)
    return {frame: PlanarPose(float(x[i]), float(y[i]), float(yaw[i]))
            for i, frame in enumerate(stations)}


def dead_reckoned(pose: PlanarPose, yaw: float, speed: float, dt: float) -> PlanarPose:
    """
    Return ``pose`` advanced by ``dt`` s at ``speed`` (m/s, along x) with heading ``yaw`` (rad).

    The real fish's odometry: no position sensor, so the position is the integral of the
    Lighthill speed estimate (eq 18) along the IMU's yaw (forward Euler); it drifts without
    bound, as dead reckoning does (REP-105 allows odom to drift, never to jump).
    """
    return PlanarPose(pose.x + speed * math.cos(yaw) * dt, pose.y + speed * math.sin(yaw) * dt,
                      yaw, pose.z)


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Return the unit quaternion (x, y, z, w) of a rotation by ``yaw`` (rad) about z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def quaternion_yaw(x: float, y: float, z: float, w: float) -> float:
    """Return the yaw (rad, about z, ZYX Euler angles) of a unit quaternion."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
