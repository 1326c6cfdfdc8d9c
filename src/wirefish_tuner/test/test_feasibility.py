# SPDX-License-Identifier: Apache-2.0
"""Feasibility of a wave and acceptance of a fit (wirefish_tuner.feasibility)."""

import math

import numpy as np
import pytest
from wirefish_kinematics.body_wave import swing_angles
from wirefish_kinematics.geometry import FishGeometry
from wirefish_tuner.feasibility import (bends_for_swing_angles, fit_rejection, FitLimits,
                                        wave_demand, wave_infeasibility)
from wirefish_tuner.wave_loss import FREQUENCY_PENALTY, WaveFitProblem, WaveSpec


def problem(**wave) -> WaveFitProblem:
    return WaveFitProblem(wave=WaveSpec(**wave))


@pytest.mark.parametrize('wave', [{}, {'c1': 0.10, 'c2': 0.8, 'k': 6.0, 'frequency_hz': 1.5},
                                  {'c1': 0.3, 'c2': 2.0}, {'frequency_hz': 2.5}])
def test_reachable_waves_are_feasible(wave):
    assert wave_infeasibility(problem(**wave)) is None


@pytest.mark.parametrize('wave, words', [
    ({'c1': 1.0e6}, 'swing angles up to 90/90 deg, beyond any bend of the tail'),
    ({'c1': 1e308}, 'servo amplitudes 3.49/4.19 rad; the servo range is +-1.571 rad'),
    ({'c2': -1e308}, 'servo amplitudes'),
    ({'c1': 0.45, 'c2': 3.0}, 'swing angles up to 34.6/44.7 deg, beyond any bend'),
    ({'k': 1.0e9}, 'k must be <= pi / 0.1 = 31.42 rad/m'),
    ({'frequency_hz': 1e-300}, 'below the slowest beat, 0.1 Hz'),
    ({'frequency_hz': 4.0}, 'the servos reach 9.1 rad/s'),
])
def test_impossible_waves_are_refused_with_what_they_ask_against_the_reach(wave, words):
    reason = wave_infeasibility(problem(**wave))
    assert reason is not None and words in reason, reason


def test_a_narrower_servo_range_refuses_what_the_default_allows():
    limits = FitLimits(servo_range_rad=0.4)
    reason = wave_infeasibility(problem(), limits)
    assert 'servo amplitudes 0.502/0.565 rad; the servo range is +-0.4 rad' in reason


def test_inverted_bends_reproduce_the_swing_angles():
    geometry = FishGeometry()
    theta = np.array([[0.1, 0.3], [-0.2, -0.1], [0.0, 0.0], [0.25, -0.2]])
    beta1, beta2 = bends_for_swing_angles(theta, geometry)
    back = np.stack(swing_angles(beta1, beta2, geometry), axis=-1)
    np.testing.assert_allclose(back, theta, atol=math.radians(0.01))


def test_the_demand_of_the_section_5_2_wave_is_a_smooth_beat_within_the_servo_range():
    demand = wave_demand(problem())
    assert demand.reachable
    np.testing.assert_allclose(demand.amplitude_rad, [0.502, 0.565], atol=1e-3)
    # The same shape twice as fast asks for twice the rate, and the same angles.
    faster = wave_demand(problem(frequency_hz=2.0))
    np.testing.assert_allclose(faster.servo_angles, demand.servo_angles)
    np.testing.assert_allclose(faster.peak_rate_rad_s, 2.0 * demand.peak_rate_rad_s)


def test_a_good_fit_is_accepted():
    assert fit_rejection(4.1e-4, np.array([0.25, 0.86])) is None


@pytest.mark.parametrize('loss, rmse, words', [
    (math.inf, [0.2, 0.8], 'not finite'),
    (math.nan, [0.2, 0.8], 'not finite'),
    (FREQUENCY_PENALTY + 0.01, [0.2, 0.8], 'penalty'),
    (0.03, [3.49, 9.12], 'RMSE theta 3.490/9.120 deg exceeds 5 deg'),
    (0.01, [math.nan, 0.5], 'RMSE'),
])
def test_bad_fits_are_refused_with_the_figures(loss, rmse, words):
    reason = fit_rejection(loss, np.array(rmse))
    assert reason is not None and words in reason, reason


@pytest.mark.parametrize('field', ['servo_range_rad', 'servo_rate_limit_rad_s',
                                   'min_frequency_hz', 'max_rmse_deg'])
@pytest.mark.parametrize('value', [0.0, -1.0, math.nan])
def test_limits_must_be_positive(field, value):
    with pytest.raises(ValueError):
        FitLimits(**{field: value})
