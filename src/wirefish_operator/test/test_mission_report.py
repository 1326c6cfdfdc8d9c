# SPDX-License-Identifier: Apache-2.0
"""The mission report: closure error, per-leg means, the PNG."""

import math

import numpy as np
import pytest
from wirefish_operator.mission_plan import mission_from
from wirefish_operator.mission_report import (from_start, plot_mission, rest_index, summarise,
                                              summary_text, Track, turn_gain_text)

MISSION = mission_from({'legs': [{'duration_s': 5.0, 'speed': 0.2},
                                 {'duration_s': 5.0, 'speed': 0.2, 'yaw_rate': 0.2}]})


def _track(end_offset: float) -> Track:
    """Return a fish that swims 1 m east, turns, and rests ``end_offset`` m from its start."""
    t = np.arange(-1.0, 12.0, 0.02)
    x = np.clip(t, 0.0, 5.0) * 0.2
    y = np.where(t > 10.0, end_offset, 0.0)
    x = np.where(t > 10.0, 0.0, x)
    yaw = np.where(t > 5.0, 0.2 * (np.minimum(t, 10.0) - 5.0), 0.0)
    speed = np.where((t >= 0.0) & (t < 10.0), 0.2, 0.0)
    rate = np.where((t >= 5.0) & (t < 10.0), 0.2, 0.0)
    return Track(t, x, y, yaw, speed, rate)


def test_closure_error_is_the_distance_from_start_to_rest():
    summary = summarise(_track(0.3), MISSION)
    assert summary.closure_error_m == pytest.approx(0.3)


def test_leg_means_are_taken_after_settling():
    summary = summarise(_track(0.0), MISSION)
    assert summary.legs[0] == pytest.approx((0.2, 0.2, 0.0, 0.0))
    assert summary.legs[1] == pytest.approx((0.2, 0.2, 0.2, 0.2))


def test_no_ground_truth_is_refused():
    empty = Track(*(np.array([]) for _ in range(6)))
    with pytest.raises(ValueError, match='ground truth'):
        summarise(empty, MISSION)


def test_the_png_is_written_and_the_summary_names_the_closure(tmp_path):
    track = _track(0.25)
    summary = summarise(track, MISSION)
    png = plot_mission(track, MISSION, summary, tmp_path / 'm.png')
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert 'closure error 0.250 m' in summary_text(MISSION, summary)
    assert not math.isnan(summary.path_length_m)


SQUARE = mission_from({'legs': [{'duration_s': 8.0, 'speed': 0.2},
                                {'duration_s': 5.0, 'speed': 0.2, 'yaw_rate': 0.3},
                                {'repeat': 3}]})


def _states(mission, offset_of_leg, gain=-9.0, bias=0.02, noise=0.0, seed=0):
    """Return (t, planner_state) at 20 Hz over ``mission``, r = gain U b + bias (+ noise)."""
    from types import SimpleNamespace

    rng = np.random.default_rng(seed)
    states = []
    for number, (begin, leg) in enumerate(zip(mission.leg_starts(), mission.legs)):
        b = offset_of_leg(number, leg)
        for t in np.arange(begin, begin + leg.duration_s, 0.05):
            rate = gain * 0.2 * b + bias + noise * rng.standard_normal()
            states.append((float(t), SimpleNamespace(mode='turn' if b else 'hold',
                                                     predicted_speed=0.2, offset=b,
                                                     yaw_rate_measured=rate)))
    return states


def _turning(number, leg):
    return -0.15 if leg.yaw_rate else 0.01 * (number % 3 - 1)


def test_the_mission_prints_a_usable_turn_gain_from_its_legs():
    text = turn_gain_text(_states(SQUARE, _turning), SQUARE, configured=-9.25)
    assert text.startswith('turn gain identified') and 'k = -9.00' in text
    assert 'd = +0.0200' in text and "the planner's turn_gain is -9.25" in text


def test_a_gain_of_the_wrong_sign_is_not_usable():
    text = turn_gain_text(_states(SQUARE, _turning, gain=3.07), SQUARE, configured=-9.25)
    assert text.startswith('turn gain: NOT usable') and 'sign' in text and 'k = 3.07' in text


def test_a_noisy_fit_is_not_usable():
    text = turn_gain_text(_states(SQUARE, _turning, noise=2.0), SQUARE, configured=-9.25)
    assert text.startswith('turn gain: NOT usable'), text


def test_too_few_legs_are_not_enough():
    three = mission_from({'legs': [{'duration_s': 8.0, 'speed': 0.2},
                                   {'duration_s': 5.0, 'speed': 0.2, 'yaw_rate': 0.3},
                                   {'duration_s': 8.0, 'speed': 0.2}]})
    text = turn_gain_text(_states(three, _turning), three)
    assert 'NOT usable from this run (only 3 legs' in text


def test_a_straight_mission_says_why_no_turn_gain():
    assert 'not identified' in turn_gain_text(_states(SQUARE, lambda n, leg: 0.0), SQUARE)


def test_the_path_is_drawn_from_the_first_legs_start():
    t = np.arange(-10, 50) / 10.0
    forward = np.clip(t, 0.0, None) * 0.2  # 0.2 m/s north from (123, 5), heading pi/2
    track = Track(t, np.full_like(t, 123.0), 5.0 + forward, np.full_like(t, math.pi / 2),
                  np.full_like(t, 0.2), np.zeros_like(t))
    moved = from_start(track)
    start = int(np.searchsorted(t, 0.0))
    assert (moved.x[start], moved.y[start]) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert moved.x[-1] == pytest.approx(forward[-1]) and moved.y[-1] == pytest.approx(0.0)
    assert np.allclose(moved.yaw, 0.0)


def test_the_rest_marker_is_where_the_fish_stopped_not_where_the_recording_ended():
    t = np.arange(-1.0, 20.0, 0.02)
    speed = np.where(t < 13.0, 0.2, 0.0)  # the fish stops 3 s after the last leg
    x = np.cumsum(speed) * 0.02
    track = Track(t, x, np.zeros_like(t), np.zeros_like(t), speed, np.zeros_like(t))
    index, rested = rest_index(track, MISSION)
    assert rested and 13.0 <= t[index] <= 13.0 + 1.0


def test_a_fish_still_swimming_at_the_end_is_said_so():
    t = np.arange(-1.0, 14.0, 0.02)
    track = Track(t, t * 0.2, np.zeros_like(t), np.zeros_like(t), np.full_like(t, 0.2),
                  np.zeros_like(t))
    index, rested = rest_index(track, MISSION)
    summary = summarise(track, MISSION)
    assert not rested and index == len(t) - 1
    assert 'still swam 0.' in summary_text(MISSION, summary)
