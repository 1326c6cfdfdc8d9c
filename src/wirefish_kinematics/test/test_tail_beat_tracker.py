# SPDX-License-Identifier: Apache-2.0
"""Tail-beat tracking over a live stream: one estimate per beat, rest, rate limit, phase."""

import math

import numpy as np
import pytest
from wirefish_kinematics.body_wave import body_positions
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.tail_beat_tracker import TailBeatTracker
from wirefish_kinematics.wire_coupling import bend_angles

G = FishGeometry()
STEP_S = 0.005


def locked(t, frequency_hz, amplitudes=(0.38, 0.47), delta=-1.2):
    w = 2 * math.pi * frequency_hz
    phases = (w * t, w * t + delta)
    return (tuple(a * math.cos(p) for a, p in zip(amplitudes, phases)),
            tuple(-a * w * math.sin(p) for a, p in zip(amplitudes, phases)))


def feed(tracker, duration_s, frequency_hz=None, start_s=0.0):
    """Add a sample every 5 ms and update after each, as the node's ticks do; return reports."""
    reports = []
    for n in range(int(round(duration_s / STEP_S))):
        t = start_s + n * STEP_S
        sample = ((0.0, 0.0), (0.0, 0.0)) if frequency_hz is None else locked(t, frequency_hz)
        ns = int(round(t * 1e9))
        tracker.history.add(100 + ns // 1_000_000_000, ns % 1_000_000_000, *sample)
        report = tracker.update(G)
        if report is not None:
            reports.append(report)
    return reports


@pytest.mark.parametrize('frequency_hz', [1.0, 2.0, 3.0])
def test_each_tail_beat_is_reported_once_with_its_frequency(frequency_hz):
    reports = feed(TailBeatTracker(2.5), 4.0, frequency_hz)
    gaps = np.diff([r.time_s for r in reports])
    np.testing.assert_allclose(gaps, 1.0 / frequency_hz, rtol=0.02)
    assert len(reports) >= int(4.0 * frequency_hz) - 2
    assert all(r.estimate.tail_beat_hz == pytest.approx(frequency_hz, rel=1e-3)
               for r in reports)


def test_a_resting_tail_reports_zero_once_per_max_period():
    reports = feed(TailBeatTracker(2.5), 6.0)
    times = [r.time_s for r in reports]
    # due once the history spans 2.5 s, then 2.5 s later; seen at the next search (<= 0.2 s)
    assert len(times) == 2 and 2.5 <= times[0] <= 2.7 and 2.5 <= times[1] - times[0] <= 2.7
    assert all(r.estimate.speed == 0.0 and r.estimate.tail_beat_hz == 0.0 for r in reports)


def test_detection_runs_at_most_once_per_detection_period():
    tracker = TailBeatTracker(2.5, detection_period_s=10.0)
    assert feed(tracker, 4.0, 2.0) == []  # the only search ran on the first sample


def test_the_phase_follows_the_lateral_position_at_q1():
    tracker = TailBeatTracker(2.5)
    feed(tracker, 3.0, 2.0)
    times, angles, _ = tracker.history.arrays()
    beta1, beta2 = bend_angles(angles[:, 0], angles[:, 1], G)
    _, y_q1 = body_positions(np.array([G.l1]), beta1, beta2, G)
    recent = times > times[-1] - 0.5
    amplitude = 0.5 * np.ptp(y_q1[recent, 0])
    phases = np.array([tracker.phase_at(t) for t in times[recent]])
    np.testing.assert_allclose(y_q1[recent, 0], amplitude * np.cos(phases), atol=0.05 * amplitude)


def test_no_phase_before_a_full_tail_beat():
    tracker = TailBeatTracker(2.5)
    feed(tracker, 0.3, 2.0)
    assert tracker.beat is None and tracker.phase_at(0.3) is None


def test_reset_forgets_samples_and_beats_so_rest_is_reported_again():
    tracker = TailBeatTracker(2.5)
    feed(tracker, 3.0)
    tracker.reset()
    assert len(tracker.history) == 0 and tracker.beat is None
    assert len(feed(tracker, 3.0)) == 1  # due again once the new history spans 2.5 s


def test_a_forgotten_beat_is_found_again_without_a_second_estimate():
    tracker = TailBeatTracker(2.5)
    feed(tracker, 3.0, 2.0)
    tracker.forget_beat()
    assert tracker.phase_at(3.0) is None
    assert feed(tracker, 0.15, 2.0, start_s=3.0) == []  # less than half a period later
    assert tracker.beat is not None


def test_a_longer_max_period_keeps_twice_as_much_history():
    tracker = TailBeatTracker(2.5)
    tracker.max_period_s = 4.0
    assert tracker.history.span_s == 8.0
