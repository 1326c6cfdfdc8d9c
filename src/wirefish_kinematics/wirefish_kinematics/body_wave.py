# SPDX-License-Identifier: Apache-2.0
"""
Body wave of the wire-driven tail in frame C0 (paper eqs 5-15, 19-20) and swing angles (5.2).

Shapes: stations ``q`` (S,) in m (any shape works), bend angles broadcast together to (...,);
results have shape (..., S). C0 (frame ``tail_base``): origin at oval plate I, x along the
initial body axis towards the tail tip, y to the right (beta > 0 bends to +y).

Stable form. With a = arc length travelled along a link and phi the turn over it, the paper's
R_L sin(phi), R_L (1 - cos(phi)) with R_L = a / phi (eqs 5-7) are rewritten as
    x = a sinc(phi),    y = a sinc(phi / 2) sin(phi / 2),      sinc(u) = sin(u) / u,
which are exact, have no division by phi and reduce to the straight segment (a, 0) at phi = 0.
The three cases of eqs 7, 8 and 12 become one expression by clipping q into each link:
    P(q) = A1 + Rot(phi1) A2 + Rot(phi1 + phi2) A3,
A1 = arc(a1, phi1), A2 = arc(a2, phi2), A3 = (a3, 0), a1 = clip(q, 0, l1),
a2 = clip(q - l1, 0, l2), a3 = clip(q - l1 - l2, 0, l3), phi1 = beta1 a1 / l1,
phi2 = beta2 a2 / l2: a downstream term is exactly zero until q reaches its link, so position
and tangent (angle phi1 + phi2) are continuous at both joints by construction.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from wirefish_kinematics.geometry import FishGeometry

# Below this |u| the derivative of sinc is summed from its Taylor series (11 terms: the first
# omitted one is < 1e-21 relative); above it the closed form loses < 3 ulp (3 eps / u^2).
_SERIES_LIMIT = 1.0
# d/du sinc(u) = -j1(u) = -sum_n (-1)^n 2 (n + 1) u^(2n + 1) / (2n + 3)!
_J1_COEFFICIENTS = tuple((-1.0) ** n * 2.0 * (n + 1) / float(np.prod(np.arange(1, 2 * n + 4)))
                         for n in range(11))


def sinc(u: ArrayLike) -> np.ndarray:
    """Return sin(u) / u (1 at u = 0), unnormalised; exact to rounding for every u."""
    u = np.asarray(u, dtype=float)
    safe = np.where(u == 0.0, 1.0, u)
    return np.where(u == 0.0, 1.0, np.sin(safe) / safe)


def sinc_derivative(u: ArrayLike) -> np.ndarray:
    """Return d sinc(u) / du = (u cos u - sin u) / u^2, without cancellation near u = 0."""
    u = np.asarray(u, dtype=float)
    small = np.abs(u) < _SERIES_LIMIT
    u2 = u * u
    series = np.zeros_like(u)
    for coefficient in reversed(_J1_COEFFICIENTS):  # Horner in u^2
        series = series * u2 + coefficient
    safe = np.where(small, 1.0, u)
    closed = (safe * np.cos(safe) - np.sin(safe)) / (safe * safe)
    derivative: np.ndarray = np.where(small, -u * series, closed)
    return derivative


def arc_point(arc_length: ArrayLike, turn: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the end (x, y) (m) of a circular arc from the origin along +x, eqs 7 and 9.

    ``arc_length`` a (m) and ``turn`` phi (rad, positive to +y) broadcast together. Equals
    (R sin(phi), R (1 - cos(phi))) with R = a / phi (eqs 5-6) and (a, 0) at phi = 0.
    """
    a = np.asarray(arc_length, dtype=float)
    half = 0.5 * np.asarray(turn, dtype=float)
    return a * sinc(2.0 * half), a * sinc(half) * np.sin(half)


def arc_point_turn_derivative(arc_length: ArrayLike, turn: ArrayLike
                              ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return d(x, y)/d(phi) (m/rad) of ``arc_point`` at fixed arc length.

    dx/dphi = a sinc'(phi); dy/dphi = a (sinc(phi) - sinc(phi/2)^2 / 2), using
    (1 - cos phi) / phi^2 = sinc(phi/2)^2 / 2, so neither form divides by phi.
    """
    a = np.asarray(arc_length, dtype=float)
    turn = np.asarray(turn, dtype=float)
    return a * sinc_derivative(turn), a * (sinc(turn) - 0.5 * sinc(0.5 * turn) ** 2)


def _rotate(angle: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return Rot(angle) (x, y), the rotation of eqs 10 and 14."""
    c, s = np.cos(angle), np.sin(angle)
    return c * x - s * y, s * x + c * y


class _Chain:
    """The clipped link coordinates of stations q for bend angles beta1, beta2 (see module)."""

    def __init__(self, q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike,
                 geometry: FishGeometry) -> None:
        q = np.asarray(q, dtype=float)
        length = geometry.tail_length
        tolerance = 1e-12 * length
        if not np.all(np.isfinite(q)) or np.any(q < -tolerance) or np.any(q > length + tolerance):
            raise ValueError(f'stations q must be finite and in [0, {length:g}] m')
        beta1, beta2 = np.broadcast_arrays(np.asarray(beta1, dtype=float),
                                           np.asarray(beta2, dtype=float))
        trailing = (1,) * q.ndim
        self.beta1 = beta1.reshape(beta1.shape + trailing)
        self.beta2 = beta2.reshape(beta2.shape + trailing)
        g = geometry
        self.a1 = np.clip(q, 0.0, g.l1)
        self.a2 = np.clip(q - g.l1, 0.0, g.l2)
        self.a3 = np.clip(q - g.l1 - g.l2, 0.0, g.l3)
        self.w1 = self.a1 / g.l1  # d(phi1)/d(beta1)
        self.w2 = self.a2 / g.l2  # d(phi2)/d(beta2)
        self.phi1 = self.beta1 * self.w1
        self.phi2 = self.beta2 * self.w2

    def downstream(self) -> tuple[np.ndarray, np.ndarray]:
        """Return Rot(phi1) A2 + Rot(phi1 + phi2) A3: the station relative to the L1 end."""
        x2, y2 = _rotate(self.phi1, *arc_point(self.a2, self.phi2))
        tangent = self.phi1 + self.phi2
        return x2 + np.cos(tangent) * self.a3, y2 + np.sin(tangent) * self.a3


def body_positions(q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike, geometry: FishGeometry
                   ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the positions (x, y) (m) in C0 of stations q for bend angles beta1, beta2, eqs 7-15.

    ``q`` (S,) arc length from plate I (m) in [0, l1 + l2 + l3]; ``beta1``, ``beta2`` (...,)
    rad; results (..., S). Raises ``ValueError`` for stations outside the tail.
    """
    chain = _Chain(q, beta1, beta2, geometry)
    x1, y1 = arc_point(chain.a1, chain.phi1)
    xd, yd = chain.downstream()
    return x1 + xd, y1 + yd


def tangent_angles(q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike, geometry: FishGeometry
                   ) -> np.ndarray:
    """Return the body-axis direction (rad) from +x at stations q, (..., S): phi1 + phi2."""
    chain = _Chain(q, beta1, beta2, geometry)
    direction: np.ndarray = chain.phi1 + chain.phi2
    return direction


def lateral_slope(q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike, geometry: FishGeometry
                  ) -> np.ndarray:
    """
    Return dy/dq (dimensionless) at stations q, (..., S); eq 19 on the fin: sin(beta1 + beta2).

    q is arc length, so dy/dq is the sine of the tangent angle on every link.
    """
    slope: np.ndarray = np.sin(tangent_angles(q, beta1, beta2, geometry))
    return slope


def lateral_bend_derivatives(q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike,
                             geometry: FishGeometry) -> tuple[np.ndarray, np.ndarray]:
    """
    Return (dy/dbeta1, dy/dbeta2) (m/rad) at stations q, (..., S): the partials of eq 20.

    Bending L1 moves plate III along d(A1)/d(phi1) and turns everything downstream rigidly
    about it (+x offset -> +y motion); bending L2 does the same from plate III on.
    """
    chain = _Chain(q, beta1, beta2, geometry)
    _, dy1 = arc_point_turn_derivative(chain.a1, chain.phi1)
    xd, _ = chain.downstream()
    d_beta1 = chain.w1 * (dy1 + xd)
    dx2, dy2 = arc_point_turn_derivative(chain.a2, chain.phi2)
    tangent = chain.phi1 + chain.phi2
    d_beta2 = chain.w2 * (np.sin(chain.phi1) * dx2 + np.cos(chain.phi1) * dy2
                          + np.cos(tangent) * chain.a3)
    return d_beta1, d_beta2


def lateral_velocity(q: ArrayLike, beta1: ArrayLike, beta2: ArrayLike, beta1_rate: ArrayLike,
                     beta2_rate: ArrayLike, geometry: FishGeometry) -> np.ndarray:
    """
    Return dy/dt (m/s) at stations q, (..., S), by the chain rule of eq 20.

    ``beta1_rate``, ``beta2_rate`` (rad/s) broadcast with the bend angles (eqs 21-22 give them
    from the servo rates).
    """
    beta1, beta2, rate1, rate2 = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (beta1, beta2, beta1_rate, beta2_rate)))
    d_beta1, d_beta2 = lateral_bend_derivatives(q, beta1, beta2, geometry)
    trailing = (1,) * np.ndim(q)
    velocity: np.ndarray = (d_beta1 * rate1.reshape(rate1.shape + trailing)
                            + d_beta2 * rate2.reshape(rate2.shape + trailing))
    return velocity


def swing_angles(beta1: ArrayLike, beta2: ArrayLike, geometry: FishGeometry
                 ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the swing angles (theta1, theta2) (rad) of section 5.2, shape of the bend angles.

    theta_i = angle(O0 Oi, O0 X0) = atan2(y, x) of the link ends O1 (q = l1), O2 (q = l1 + l2).
    """
    x, y = body_positions(np.array(geometry.link_end_stations), beta1, beta2, geometry)
    theta = np.arctan2(y, x)
    return theta[..., 0], theta[..., 1]
