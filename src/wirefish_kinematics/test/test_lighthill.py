# SPDX-License-Identifier: Apache-2.0
"""Lighthill speed estimate, eqs 16-22."""

import math

import numpy as np
import pytest
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (drag_coefficient_for_speed, drag_force,
                                           estimate_speed, instantaneous_thrust, steady_speed,
                                           tail_tip_velocity_and_slope)

G = FishGeometry()
N = 256


def one_period(frequency_hz: float, scale: float = 1.0, delta: float = -1.2):
    """Locked servo sinusoids (Table 1 amplitudes times scale) over one period."""
    dt = 1.0 / (N * frequency_hz)
    w = 2 * math.pi * frequency_hz
    t = np.arange(N) * dt
    amplitudes = scale * np.array([0.38, 0.47])
    phases = w * t[:, None] + np.array([0.0, delta])
    return amplitudes * np.cos(phases), -amplitudes * w * np.sin(phases), dt


def speed(frequency_hz: float, scale: float = 1.0) -> float:
    return estimate_speed(*one_period(frequency_hz, scale), G).speed


@pytest.mark.parametrize('low, high', [(0.5, 1.0), (1.0, 3.0), (3.0, 6.5)])
def test_speed_grows_with_frequency_at_fixed_shape(low, high):
    assert speed(high) > speed(low)


@pytest.mark.parametrize('low, high', [(0.1, 0.3), (0.3, 1.0), (1.0, 1.5)])
def test_speed_grows_with_amplitude_at_fixed_frequency(low, high):
    assert speed(2.0, high) > speed(2.0, low)


def test_speed_is_proportional_to_frequency_at_fixed_shape():
    # v scales with f, the slope does not (eqs 18-20)
    assert speed(4.0) == pytest.approx(2.0 * speed(2.0), rel=1e-12)


@pytest.mark.parametrize('frequency_hz', [0.5, 3.0])
def test_zero_amplitude_gives_zero_speed_thrust_and_drag(frequency_hz):
    result = estimate_speed(*one_period(frequency_hz, 0.0), G)
    assert (result.speed, result.thrust, result.drag, result.swimming_number,
            result.tail_tip_amplitude) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_mean_thrust_balances_drag_at_the_steady_speed():
    result = estimate_speed(*one_period(3.0), G)
    assert result.thrust == pytest.approx(result.drag, rel=1e-12)
    assert result.drag == pytest.approx(0.5 * G.drag_coefficient * G.water_density
                                        * result.speed ** 2 * G.wetted_area, rel=1e-14)


def test_summary_fields_follow_their_definitions():
    angles, rates, dt = one_period(2.0)
    result = estimate_speed(angles, rates, dt, G)
    assert result.tail_beat_hz == pytest.approx(2.0, rel=1e-14)
    assert result.swimming_number == pytest.approx(result.speed / (2.0 * G.body_length),
                                                   rel=1e-14)
    v, s = tail_tip_velocity_and_slope(angles, rates, G)
    assert result.speed == pytest.approx(
        math.sqrt(G.tip_cross_section_area * np.mean(v ** 2)
                  / (G.drag_coefficient * G.wetted_area
                     + G.tip_cross_section_area * np.mean(s ** 2))), rel=1e-14)
    assert 0.04 < result.tail_tip_amplitude < 0.12


def test_instantaneous_thrust_is_the_integrand_of_eq_16():
    value = instantaneous_thrust(0.5, 0.3, 0.4, G)
    expected = 0.5 * 1000 * G.tip_cross_section_area * (0.25 - 0.16 * 0.09)
    assert value == pytest.approx(expected, rel=1e-15)


def test_drag_opposes_the_motion():
    assert drag_force(-0.3, G) == pytest.approx(-drag_force(0.3, G), rel=0)
    assert drag_force(0.0, G) == 0.0


@pytest.mark.parametrize('mean_v2, mean_s2', [(0.1, 0.2), (0.5, 0.0), (2.0, 0.6)])
def test_drag_coefficient_for_speed_inverts_eq_18(mean_v2, mean_s2):
    u = float(steady_speed(mean_v2, mean_s2, G))
    assert drag_coefficient_for_speed(u, mean_v2, mean_s2, G) == pytest.approx(
        G.drag_coefficient, rel=1e-12)


BAD_INPUTS = [
    (np.zeros((4, 3)), np.zeros((4, 3)), 0.01, 'T, 2'),
    (np.zeros((4, 2)), np.zeros((5, 2)), 0.01, 'T, 2'),
    (np.zeros((1, 2)), np.zeros((1, 2)), 0.01, 'at least 2'),
    (np.full((4, 2), np.nan), np.zeros((4, 2)), 0.01, 'finite'),
    (np.zeros((4, 2)), np.zeros((4, 2)), 0.0, 'dt'),
]


@pytest.mark.parametrize('angles, rates, dt, reason', BAD_INPUTS)
def test_invalid_samples_are_refused_with_a_reason(angles, rates, dt, reason):
    with pytest.raises(ValueError, match=reason):
        estimate_speed(angles, rates, dt, G)
