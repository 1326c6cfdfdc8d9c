"""The mission report: closure error, per-leg means, the PNG."""

import math

import numpy as np
import pytest
from wirefish_planner.mission_plan import mission_from
from wirefish_planner.mission_report import (plot_mission, summarise, summary_text, Track,
                                             turn_gain_text)

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


def _states(offsets):
    """Return (t, planner_state) pairs at 20 Hz with r = -9 U b + 0.02 for these offsets."""
    from types import SimpleNamespace

    states = []
    for i, b in enumerate(offsets):
        states.append((i * 0.05, SimpleNamespace(mode='turn', predicted_speed=0.2, offset=b,
                                                 yaw_rate_measured=-9.0 * 0.2 * b + 0.02)))
    return states


def test_the_mission_prints_the_turn_gain_it_identifies():
    offsets = [0.0] * 60 + [-0.1] * 100 + [0.1] * 100
    assert 'k = -9.00' in turn_gain_text(_states(offsets))
    assert 'd = +0.0200' in turn_gain_text(_states(offsets))


def test_a_straight_mission_says_why_no_turn_gain():
    assert 'not identified' in turn_gain_text(_states([0.0] * 100))
