# SPDX-License-Identifier: Apache-2.0
"""The yaw-rate PI, heading reference, feed-forward and filters."""

import math

import numpy as np
import pytest
from wirefish_planner.yaw_control import (feedforward_offset, heading_rate_reference,
                                          identify_turn_gain, PeriodMean, wrap_angle,
                                          yaw_from_quaternion, YawGains, YawRatePi)


@pytest.mark.parametrize('yaw', [-3.0, -1.0, 0.0, 0.5, 2.9])
def test_yaw_from_quaternion_of_a_rotation_about_z(yaw):
    assert yaw_from_quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)) == \
        pytest.approx(yaw)


def test_heading_reference_takes_the_short_way_round():
    # Target just left of -pi, heading just right of +pi: a small left turn, not a full one.
    assert heading_rate_reference(-3.1, 3.1, 1.0, 10.0) == pytest.approx(
        wrap_angle(-3.1 - 3.1))
    assert heading_rate_reference(-3.1, 3.1, 1.0, 10.0) > 0.0


def test_heading_reference_is_limited():
    assert heading_rate_reference(1.0, 0.0, 5.0, 0.3) == 0.3


def test_feedforward_inverts_the_plant_model():
    gains = YawGains()
    b = feedforward_offset(0.2, 0.25, gains.turn_gain)
    assert gains.turn_gain * 0.25 * b == pytest.approx(0.2)


def test_no_turning_without_speed():
    pi = YawRatePi(YawGains())
    assert pi.update(0.2, 0.0, 0.01, 0.0) == 0.0 and pi.integral == 0.0


def test_integrator_uses_the_given_dt():
    pi_short, pi_long = YawRatePi(YawGains()), YawRatePi(YawGains())
    pi_short.update(0.0, -0.1, 0.01, 0.2)
    pi_long.update(0.0, -0.1, 0.04, 0.2)
    assert pi_long.integral == pytest.approx(4.0 * pi_short.integral)


def test_output_is_limited_and_the_integrator_does_not_wind_up():
    gains = YawGains(max_offset_rad=0.1)
    pi = YawRatePi(gains)
    for _ in range(2000):  # a yaw rate the offsets cannot reach, for 20 s
        pi.update(1.0, 0.0, 0.01, 0.2)
    assert abs(pi.offset) == pytest.approx(0.1) and pi.saturated
    wound = pi.integral
    # One step of an error that wants the other way leaves saturation at once.
    pi.update(-0.05, 0.0, 0.01, 0.2)
    assert abs(pi.offset) < 0.1
    assert abs(wound) < gains.integral_limit


def test_the_offset_turns_the_right_way():
    # k < 0: a left turn (r > 0) needs the tail held left (b < 0).
    assert YawRatePi(YawGains()).update(0.2, 0.0, 0.01, 0.2) < 0.0


def test_period_mean_removes_an_oscillation_at_the_window():
    mean = PeriodMean(0.5)
    value = math.nan
    for i in range(300):
        t = i * 0.01
        value = mean.add(t, 0.1 + math.sin(2 * math.pi * 2.0 * t))
    assert value == pytest.approx(0.1, abs=0.01)


@pytest.mark.parametrize('field', ['kp', 'ki', 'max_offset_rad'])
def test_negative_gains_are_refused(field):
    with pytest.raises(ValueError):
        YawGains(**{field: -1.0})


def test_zero_turn_gain_is_refused():
    with pytest.raises(ValueError):
        YawGains(turn_gain=0.0)


def test_turn_gain_identification_recovers_gain_and_disturbance():
    rng = np.random.default_rng(1)
    speed = np.full(400, 0.2)
    offset = rng.uniform(-0.1, 0.1, 400)
    rate = -9.0 * speed * offset + 0.05 + rng.normal(0.0, 0.01, 400)
    gain, bias = identify_turn_gain(speed, offset, rate)
    assert gain == pytest.approx(-9.0, rel=0.05) and bias == pytest.approx(0.05, abs=0.005)


def test_a_straight_run_cannot_identify_the_turn_gain():
    with pytest.raises(ValueError, match='turn'):
        identify_turn_gain(np.full(50, 0.2), np.zeros(50), np.zeros(50))
