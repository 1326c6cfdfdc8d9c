# SPDX-License-Identifier: Apache-2.0
"""
Lighthill's elongated-body speed estimate (paper eqs 16-22).

Thrust comes from the lateral velocity dy/dt and slope dy/dq of the tail tip q = L_T (eq 16),
drag from eq 17; their balance gives the steady speed U_c (eq 18). Means are over one
tail-beat period of uniformly spaced samples (rectangle rule, the natural quadrature of a
periodic integrand).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from wirefish_kinematics.body_wave import body_positions, lateral_slope, lateral_velocity
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import bend_angles, bend_rates


def instantaneous_thrust(tip_lateral_velocity: ArrayLike, tip_slope: ArrayLike,
                         speed: ArrayLike, geometry: FishGeometry) -> np.ndarray:
    """
    Return rho A(L_T) / 2 ((dy/dt)^2 - U^2 (dy/dq)^2) (N), the integrand of eq 16.

    Its mean over a period is the mean thrust F_T. Arguments (m/s, -, m/s) broadcast.
    """
    v = np.asarray(tip_lateral_velocity, dtype=float)
    slope = np.asarray(tip_slope, dtype=float)
    u = np.asarray(speed, dtype=float)
    area = geometry.tip_cross_section_area
    thrust: np.ndarray = 0.5 * geometry.water_density * area * (v * v - u * u * slope * slope)
    return thrust


def drag_force(speed: ArrayLike, geometry: FishGeometry) -> np.ndarray:
    """
    Return the drag F_D = C_D rho U |U| S_c / 2 (N) of eq 17, opposing the motion.

    Equal to eq 17 for U >= 0; the sign makes it usable for surge dynamics in both directions.
    """
    u = np.asarray(speed, dtype=float)
    g = geometry
    drag: np.ndarray = 0.5 * g.drag_coefficient * g.water_density * u * np.abs(u) * g.wetted_area
    return drag


def steady_speed(mean_square_lateral_velocity: ArrayLike, mean_square_slope: ArrayLike,
                 geometry: FishGeometry) -> np.ndarray:
    """
    Return U_c (m/s) of eq 18, where the mean thrust (eq 16) balances the drag (eq 17).

    Arguments: the period means of (dy/dt)^2 (m^2/s^2) and (dy/dq)^2 at the tail tip.
    """
    g = geometry
    rho_a = g.water_density * g.tip_cross_section_area
    numerator = rho_a * np.asarray(mean_square_lateral_velocity, dtype=float)
    denominator = (g.water_density * g.drag_coefficient * g.wetted_area
                   + rho_a * np.asarray(mean_square_slope, dtype=float))
    return np.sqrt(numerator / denominator)


def drag_coefficient_for_speed(speed: float, mean_square_lateral_velocity: float,
                               mean_square_slope: float, geometry: FishGeometry) -> float:
    """
    Return the C_D for which eq 18 gives ``speed`` (m/s): eq 18 solved for C_D.

    C_D = A(L_T) (<(dy/dt)^2> / U^2 - <(dy/dq)^2>) / S_c; the other fields of ``geometry``
    are used, its drag_coefficient is not.
    """
    area = geometry.tip_cross_section_area
    return area * (mean_square_lateral_velocity / speed ** 2 - mean_square_slope) / (
        geometry.wetted_area)


@dataclass(frozen=True)
class SpeedEstimate:
    """The eq 16-22 estimate over one tail-beat period (fields as wirefish_msgs/SpeedEstimate)."""

    speed: float  # U_c (m/s), eq 18
    thrust: float  # mean thrust F_T at U_c (N), eq 16
    drag: float  # F_D at U_c (N), eq 17
    swimming_number: float  # Sw = U / (f L), section 5.4
    tail_beat_hz: float  # f (Hz)
    tail_tip_amplitude: float  # half peak-to-peak lateral excursion of the tip (m)


def tail_tip_lateral_positions(servo_angles: ArrayLike, geometry: FishGeometry) -> np.ndarray:
    """Return y(L_T) (m) of servo angles (..., 2) (rad): the tail tip's lateral position."""
    angles = np.asarray(servo_angles, dtype=float)
    beta1, beta2 = bend_angles(angles[..., 0], angles[..., 1], geometry)
    _, y = body_positions(np.array([geometry.tail_length]), beta1, beta2, geometry)
    return y[..., 0]


def tail_tip_velocity_and_slope(servo_angles: ArrayLike, servo_rates: ArrayLike,
                                geometry: FishGeometry) -> tuple[np.ndarray, np.ndarray]:
    """
    Return dy/dt (m/s, eq 20 with eqs 21-22) and dy/dq (eq 19) at the tail tip, each (...,).

    ``servo_angles`` (..., 2) rad and ``servo_rates`` (..., 2) rad/s.
    """
    angles = np.asarray(servo_angles, dtype=float)
    rates = np.asarray(servo_rates, dtype=float)
    tip = np.array([geometry.tail_length])
    beta1, beta2 = bend_angles(angles[..., 0], angles[..., 1], geometry)
    rate1, rate2 = bend_rates(rates[..., 0], rates[..., 1], geometry)
    velocity = lateral_velocity(tip, beta1, beta2, rate1, rate2, geometry)[..., 0]
    return velocity, lateral_slope(tip, beta1, beta2, geometry)[..., 0]


def estimate_speed(servo_angles: ArrayLike, servo_rates: ArrayLike, dt: float,
                   geometry: FishGeometry) -> SpeedEstimate:
    """
    Return the steady-speed estimate (eqs 16-22) of one tail-beat period of servo samples.

    ``servo_angles`` (T, 2) rad and ``servo_rates`` (T, 2) rad/s sampled every ``dt`` s at
    t0 + n dt, n = 0..T-1, with T dt one period (the end point is the next period's start).
    dy/dt at the tip comes from the chain rule (eq 20) with eqs 21-22. Raises ``ValueError``
    for mismatched shapes, fewer than 2 samples, non-finite values or dt <= 0.
    """
    angles = np.asarray(servo_angles, dtype=float)
    rates = np.asarray(servo_rates, dtype=float)
    if angles.ndim != 2 or angles.shape[1] != 2 or rates.shape != angles.shape:
        raise ValueError(f'servo angles and rates must both be (T, 2), got {angles.shape} '
                         f'and {rates.shape}')
    if angles.shape[0] < 2:
        raise ValueError('need at least 2 samples of one period')
    if not (np.all(np.isfinite(angles)) and np.all(np.isfinite(rates))):
        raise ValueError('servo angles and rates must be finite')
    if not (np.isfinite(dt) and dt > 0.0):
        raise ValueError(f'dt must be finite and > 0, got {dt}')
    velocity, slope = tail_tip_velocity_and_slope(angles, rates, geometry)
    speed = float(steady_speed(np.mean(velocity ** 2), np.mean(slope ** 2), geometry))
    thrust = float(np.mean(instantaneous_thrust(velocity, slope, speed, geometry)))
    frequency = 1.0 / (angles.shape[0] * float(dt))
    y_tip = tail_tip_lateral_positions(angles, geometry)
    return SpeedEstimate(speed=speed, thrust=thrust,
                         drag=float(drag_force(speed, geometry)),
                         swimming_number=speed / (frequency * geometry.body_length),
                         tail_beat_hz=frequency,
                         tail_tip_amplitude=0.5 * float(np.ptp(y_tip)))


# --- Lighthill's time-resolved reactive force (the virtual fish's thrust) ------------------
#
# Eq 16 is the period mean of Lighthill's (1960) instantaneous reactive thrust
#     T(t) = [m w dy/dt - m w^2 / 2]_(q = L_T) - d/dt int_0^L_T m w dy/dq dq,
# with w = dy/dt + U dy/dq the water's lateral velocity relative to the body and m(q) the
# lateral added mass per unit length. The tip term equals the eq 16 integrand
# (``instantaneous_thrust``); the last term is the rate of change of the lateral momentum
# shed along the tail, whose period mean is zero. With G = K1 + U K2,
#     K1 = int m dy/dt dy/dq dq,    K2 = int m (dy/dq)^2 dq,
# dG/dt = K1' + U K2' + U' K2: the U' K2 part is inertia (it joins the mass in the surge
# equation). Model assumption: m(q) = rho A(L_T) along the whole tail (the paper gives the
# cross-section only at the tip; the fish is about as deep, 150 mm, as the fin's 140 mm span);
# the rigid head (q < 0) does not move laterally in C0 and sheds nothing.
TAIL_GAUSS_POINTS = 4  # Gauss-Legendre points per link (the integrands are smooth on each)
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(TAIL_GAUSS_POINTS)


def tail_quadrature(geometry: FishGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Return stations q (S,) m and weights (S,) m integrating over [0, L_T] link by link."""
    edges = np.cumsum([0.0, geometry.l1, geometry.l2, geometry.l3])
    half = 0.5 * np.diff(edges)
    stations = (edges[:-1, None] + half[:, None] * (_GAUSS_NODES + 1.0)).ravel()
    return stations, (half[:, None] * _GAUSS_WEIGHTS).ravel()


def lateral_added_mass_per_length(geometry: FishGeometry) -> float:
    """Return m = rho A(L_T) (kg/m), the lateral added mass per unit length (assumption)."""
    return geometry.water_density * geometry.tip_cross_section_area


def reactive_state(servo_angles: ArrayLike, servo_rates: ArrayLike, geometry: FishGeometry
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Return (dy/dt, dy/dq at the tip, K1 (kg m/s), K2 (kg)) of servo samples (..., 2), each (...,).

    The tip's lateral velocity and slope as ``tail_tip_velocity_and_slope`` (eqs 19-22);
    K1 = int m dy/dt dy/dq dq and K2 = int m (dy/dq)^2 dq over the tail (see above): the
    lateral momentum of the water along the tail is K1 + U K2. One kinematics evaluation
    serves all four (the virtual fish calls this every physics block).
    """
    angles = np.asarray(servo_angles, dtype=float)
    rates = np.asarray(servo_rates, dtype=float)
    stations, weights = tail_quadrature(geometry)
    stations = np.append(stations, geometry.tail_length)
    beta1, beta2 = bend_angles(angles[..., 0], angles[..., 1], geometry)
    rate1, rate2 = bend_rates(rates[..., 0], rates[..., 1], geometry)
    velocity = lateral_velocity(stations, beta1, beta2, rate1, rate2, geometry)
    slope = lateral_slope(stations, beta1, beta2, geometry)
    m = lateral_added_mass_per_length(geometry)
    k1 = m * (velocity[..., :-1] * slope[..., :-1]) @ weights
    k2 = m * (slope[..., :-1] * slope[..., :-1]) @ weights
    return velocity[..., -1], slope[..., -1], k1, k2
