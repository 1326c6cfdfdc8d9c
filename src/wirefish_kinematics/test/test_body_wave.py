# SPDX-License-Identifier: Apache-2.0
"""Body wave, eqs 7-15 and 19-20: exactness, stability at beta -> 0, continuity, symmetry."""

import math

import numpy as np
import pytest
from wirefish_kinematics.body_wave import (arc_point, body_positions, lateral_bend_derivatives,
                                           lateral_slope, lateral_velocity, sinc_derivative,
                                           swing_angles, tangent_angles)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import bend_angles, bend_rates

G = FishGeometry()
L = G.tail_length
BENDS = [(0.0, 0.0), (0.342, -0.36), (-0.9, 1.4), (1e-9, -2e-9), (2.5, 2.5), (0.0, -1.0),
         (1.0, 0.0)]


def paper_positions(q: float, beta1: float, beta2: float) -> tuple[float, float]:
    """Eqs 5-15 exactly as printed (nonzero bends only), one station."""
    l1, l2 = G.l1, G.l2
    r1, r2 = l1 / beta1, l2 / beta2
    if q <= l1:
        return r1 * math.sin(q * beta1 / l1), r1 * (1 - math.cos(q * beta1 / l1))
    rot1 = np.array([[math.cos(beta1), -math.sin(beta1)], [math.sin(beta1), math.cos(beta1)]])
    p1 = np.array([r1 * math.sin(beta1), r1 * (1 - math.cos(beta1))])
    if q <= l1 + l2:
        a = (q - l1) * beta2 / l2
        return tuple(rot1 @ [r2 * math.sin(a), r2 * (1 - math.cos(a))] + p1)
    b = beta1 + beta2
    rot2 = np.array([[math.cos(b), -math.sin(b)], [math.sin(b), math.cos(b)]])
    p2 = rot1 @ [r2 * math.sin(beta2), r2 * (1 - math.cos(beta2))] + p1
    return tuple(rot2 @ [q - l1 - l2, 0.0] + p2)


@pytest.mark.parametrize('beta1, beta2', [(0.342, -0.36), (-0.9, 1.4), (2.5, 2.5)])
@pytest.mark.parametrize('q', [0.0, 0.03, 0.08, 0.1, 0.18, 0.2, 0.24])
def test_positions_equal_the_printed_eqs_7_to_15_for_nonzero_bends(q, beta1, beta2):
    x, y = body_positions(np.array([q]), beta1, beta2, G)
    np.testing.assert_allclose([x[0], y[0]], paper_positions(q, beta1, beta2), atol=1e-15)


@pytest.mark.parametrize('beta', [0.0, 1e-300, -1e-15, 1e-13])
def test_zero_bend_limit_is_the_straight_segment_to_1e_12_m(beta):
    q = np.linspace(0.0, L, 241)
    x, y = body_positions(q, beta, beta, G)
    np.testing.assert_allclose(x, q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(y, 0.0, rtol=0, atol=1e-12)
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(y))


@pytest.mark.parametrize('turn', [1e-12, 1e-8, 1e-5, 1e-3, -3e-4])
def test_small_arcs_keep_full_relative_precision(turn):
    # Taylor series of a (1 - cos phi) / phi and a sin(phi) / phi: exact to 1e-17 here;
    # the printed R (1 - cos) form would lose up to all digits at these turns.
    a = 0.1
    x, y = arc_point(a, turn)
    assert y == pytest.approx(a * (turn / 2 - turn ** 3 / 24 + turn ** 5 / 720), rel=2e-16)
    assert x == pytest.approx(a * (1 - turn ** 2 / 6 + turn ** 4 / 120), rel=2e-16)


@pytest.mark.parametrize('u', [1e-12, 1e-6, 1e-3, 0.1, 0.5])
def test_sinc_derivative_series_matches_its_taylor_expansion(u):
    taylor = (-u / 3 + u ** 3 / 30 - u ** 5 / 840 + u ** 7 / 45360 - u ** 9 / 3991680
              + u ** 11 / 518918400)
    assert sinc_derivative(u) == pytest.approx(taylor, rel=1e-13 if u > 0.3 else 2e-15)


def test_sinc_derivative_is_continuous_across_the_series_limit():
    below, above = sinc_derivative(np.nextafter(1.0, 0.0)), sinc_derivative(1.0)
    assert below == pytest.approx(above, rel=1e-14)
    assert above == pytest.approx(math.cos(1.0) - math.sin(1.0), rel=1e-15)


@pytest.mark.parametrize('beta1, beta2', BENDS)
@pytest.mark.parametrize('joint', ['l1', 'l1+l2'])
def test_position_and_tangent_are_continuous_at_the_joints(beta1, beta2, joint):
    q0 = G.l1 if joint == 'l1' else G.l1 + G.l2
    eps = 1e-9
    q = np.array([q0 - eps, q0, q0 + eps])
    x, y = body_positions(q, beta1, beta2, G)
    steps = np.hypot(np.diff(x), np.diff(y))
    np.testing.assert_allclose(steps, eps, rtol=1e-5)  # no jump: unit-speed curve
    angle = tangent_angles(q, beta1, beta2, G)
    assert np.ptp(angle) <= 1e-8 * (abs(beta1) + abs(beta2) + 1)
    # the tangent of the position itself, from each side
    left = np.arctan2(y[1] - y[0], x[1] - x[0])
    right = np.arctan2(y[2] - y[1], x[2] - x[1])
    assert left == pytest.approx(right, abs=1e-6)


@pytest.mark.parametrize('beta1, beta2', BENDS)
def test_arc_length_of_the_curve_is_the_tail_length(beta1, beta2):
    q = np.linspace(0.0, L, 200_001)
    x, y = body_positions(q, beta1, beta2, G)
    length = math.fsum(np.hypot(np.diff(x), np.diff(y)))
    assert length == pytest.approx(L, rel=1e-9)


@pytest.mark.parametrize('servo', [(0.38, 0.47), (0.2, -0.3), (1e-10, 0.0), (-1.0, 1.2)])
def test_negating_both_servo_angles_mirrors_y(servo):
    q = np.linspace(0.0, L, 50)
    x, y = body_positions(q, *bend_angles(*servo, G), G)
    xm, ym = body_positions(q, *bend_angles(-servo[0], -servo[1], G), G)
    np.testing.assert_array_equal(xm, x)
    np.testing.assert_array_equal(ym, -y)


def servo_trajectory(t, frequency_hz, amplitudes=(0.38, 0.47), delta=-1.2):
    w = 2 * math.pi * frequency_hz
    angles = np.stack([amplitudes[0] * np.cos(w * t), amplitudes[1] * np.cos(w * t + delta)],
                      axis=-1)
    rates = np.stack([-amplitudes[0] * w * np.sin(w * t),
                      -amplitudes[1] * w * np.sin(w * t + delta)], axis=-1)
    return angles, rates


@pytest.mark.parametrize('frequency_hz, amplitudes', [(1.0, (0.38, 0.47)), (3.0, (0.2, -0.6)),
                                                      (6.5, (1e-7, 2e-7))])
def test_chain_rule_velocity_matches_central_differences_in_time(frequency_hz, amplitudes):
    q = np.linspace(0.0, L, 25)
    t = np.linspace(0.0, 1.0 / frequency_hz, 40)
    h = 1e-5 / frequency_hz
    angles, rates = servo_trajectory(t, frequency_hz, amplitudes)
    beta = bend_angles(angles[:, 0], angles[:, 1], G)
    v = lateral_velocity(q, *beta, *bend_rates(rates[:, 0], rates[:, 1], G), G)
    ys = [body_positions(q, *bend_angles(a[:, 0], a[:, 1], G), G)[1]
          for a in (servo_trajectory(t + h, frequency_hz, amplitudes)[0],
                    servo_trajectory(t - h, frequency_hz, amplitudes)[0])]
    difference = (ys[0] - ys[1]) / (2 * h)
    assert v.shape == (40, 25)
    assert np.max(np.abs(v - difference)) <= 1e-6 * np.max(np.abs(v))


@pytest.mark.parametrize('beta1, beta2', BENDS)
def test_bend_derivatives_match_central_differences(beta1, beta2):
    q = np.linspace(0.0, L, 25)
    h = 1e-6
    d1, d2 = lateral_bend_derivatives(q, beta1, beta2, G)
    f1 = (body_positions(q, beta1 + h, beta2, G)[1]
          - body_positions(q, beta1 - h, beta2, G)[1]) / (2 * h)
    f2 = (body_positions(q, beta1, beta2 + h, G)[1]
          - body_positions(q, beta1, beta2 - h, G)[1]) / (2 * h)
    np.testing.assert_allclose(d1, f1, rtol=0, atol=1e-8)
    np.testing.assert_allclose(d2, f2, rtol=0, atol=1e-8)


@pytest.mark.parametrize('beta1, beta2', BENDS)
def test_slope_on_the_fin_is_eq_19(beta1, beta2):
    q = np.array([G.l1 + G.l2, 0.22, L])
    np.testing.assert_allclose(lateral_slope(q, beta1, beta2, G), math.sin(beta1 + beta2),
                               atol=1e-15)


@pytest.mark.parametrize('beta1, beta2', BENDS)
def test_swing_angles_are_those_of_the_chords(beta1, beta2):
    # The chord of a circular arc makes half the arc's turn with its start tangent.
    theta1, theta2 = swing_angles(beta1, beta2, G)
    assert theta1 == pytest.approx(beta1 / 2, abs=1e-15)
    # O2 from the chords instead of eqs 7-15: arc i's chord is 2 l_i sin(b_i/2) / b_i long
    # (l_i when straight) and leaves at the start tangent plus half the arc's turn.

    def chord(length: float, bend: float) -> float:
        return length if bend == 0.0 else 2.0 * length * math.sin(bend / 2) / bend
    o2_x = (chord(G.l1, beta1) * math.cos(beta1 / 2)
            + chord(G.l2, beta2) * math.cos(beta1 + beta2 / 2))
    o2_y = (chord(G.l1, beta1) * math.sin(beta1 / 2)
            + chord(G.l2, beta2) * math.sin(beta1 + beta2 / 2))
    assert theta2 == pytest.approx(math.atan2(o2_y, o2_x), abs=1e-12)


def test_shapes_broadcast_bends_before_stations():
    q = np.linspace(0.0, L, 7)
    x, y = body_positions(q, np.zeros((4, 3)), np.zeros(3), G)
    assert x.shape == y.shape == (4, 3, 7)
    theta1, theta2 = swing_angles(np.zeros((4, 3)), 0.1, G)
    assert theta1.shape == theta2.shape == (4, 3)


@pytest.mark.parametrize('q', [-1e-3, L + 1e-3, math.nan])
def test_stations_outside_the_tail_are_refused(q):
    with pytest.raises(ValueError, match='stations'):
        body_positions(np.array([0.0, q]), 0.1, 0.1, G)
