# SPDX-License-Identifier: Apache-2.0
"""Desired wave, eq 23, and the expected swing angles of section 5.2."""

import math

import numpy as np
import pytest
from wirefish_kinematics.desired_wave import (desired_lateral_position, desired_swing_angles,
                                              desired_wave_at_phase, wave_time_at_phase,
                                              WAVE_TIME_SIGN)
from wirefish_kinematics.geometry import FishGeometry

G = FishGeometry()
WAVE = (0.15, 1.0, 8.0, 1.0)  # section 5.2


def test_eq_23_value():
    q, t = 0.1, 0.2
    expected = (0.15 * q + q * q) * math.sin(8 * q - 2 * math.pi * t)
    assert desired_lateral_position(q, t, *WAVE) == pytest.approx(expected, rel=1e-15)


def test_default_wave_travels_towards_the_tail():
    assert WAVE_TIME_SIGN == -1.0
    # a crest at phase pi/2 sits at q = (pi/2 + omega t) / k: later, further back
    crest = [(math.pi / 2 + 2 * math.pi * t) / 8.0 for t in (0.0, 0.01)]
    for q, t in zip(crest, (0.0, 0.01)):
        assert math.sin(8 * q - 2 * math.pi * t) == pytest.approx(1.0)
        assert desired_lateral_position(q, t, *WAVE) == pytest.approx(0.15 * q + q * q)
    assert crest[1] > crest[0]


def test_time_sign_keyword_evaluates_the_printed_head_ward_wave():
    q, t = 0.1, 0.2
    value = desired_lateral_position(q, t, *WAVE, time_sign=1.0)
    assert value == pytest.approx((0.15 * q + q * q) * math.sin(8 * q + 2 * math.pi * t))


def test_grid_by_broadcasting():
    q = np.linspace(0, G.tail_length, 5)
    t = np.linspace(0, 1, 3)
    assert desired_lateral_position(q[None, :], t[:, None], *WAVE).shape == (3, 5)


def test_expected_swing_angles_point_at_the_wave_at_the_link_ends():
    t = np.linspace(0, 1, 9)
    theta1, theta2 = desired_swing_angles(t, *WAVE, G)
    for theta, q in zip((theta1, theta2), G.link_end_stations):
        np.testing.assert_allclose(np.tan(theta) * q, desired_lateral_position(q, t, *WAVE),
                                   atol=1e-15)


@pytest.mark.parametrize('time_sign', [-1.0, 1.0])
@pytest.mark.parametrize('phase', [0.0, 1.0, -2.5, 7.0])
def test_wave_time_at_phase_puts_the_wave_at_q1_in_phase(time_sign, phase):
    tau = wave_time_at_phase(phase, G.l1, 8.0, 1.0, time_sign)
    envelope = 0.15 * G.l1 + G.l1 ** 2
    y = desired_lateral_position(G.l1, tau, *WAVE, time_sign=time_sign)
    assert y == pytest.approx(envelope * math.cos(phase), abs=1e-15)
    later = wave_time_at_phase(phase + 0.1, G.l1, 8.0, 1.0, time_sign)
    assert later > tau


@pytest.mark.parametrize('c1, c2', [(0.15, 1.0), (-0.15, -1.0)])
@pytest.mark.parametrize('phase', [0.0, 1.0, -2.5])
def test_the_overlay_at_q1_has_the_sign_of_the_tail_at_its_phase(c1, c2, phase):
    stations = np.array([G.l1, G.tail_length])
    y = desired_wave_at_phase(stations, phase, G.l1, c1, c2, 8.0, 1.0)
    envelope = abs(c1 * G.l1 + c2 * G.l1 ** 2)
    assert y[0] == pytest.approx(envelope * math.cos(phase), abs=1e-15)
