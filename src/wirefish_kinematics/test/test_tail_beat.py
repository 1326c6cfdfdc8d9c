# SPDX-License-Identifier: Apache-2.0
"""Tail-beat window and estimate from unevenly stamped samples."""

import math

import numpy as np
import pytest
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import estimate_speed, tail_tip_lateral_positions
from wirefish_kinematics.servo_history import ServoHistory
from wirefish_kinematics.tail_beat import (estimate_speed_over, fundamental_phase,
                                           last_tail_beat, upward_crossings)

G = FishGeometry()


def stream(frequency_hz, duration_s=3.0, seed=0, amplitudes=(0.38, 0.47), delta=-1.2):
    """Locked servo sinusoids at jittered instants (4-6 ms apart)."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.004, 0.006, int(duration_s / 0.005)))
    w = 2 * math.pi * frequency_hz
    phases = w * t[:, None] + np.array([0.0, delta])
    a = np.asarray(amplitudes)
    return t, a * np.cos(phases), -a * w * np.sin(phases)


@pytest.mark.parametrize('frequency_hz', [0.7, 1.0, 2.0, 3.0, 6.5])
def test_last_tail_beat_finds_the_period_of_a_jittered_stream(frequency_hz):
    t, angles, _ = stream(frequency_hz)
    beat = last_tail_beat(t, tail_tip_lateral_positions(angles, G), 1e-4)
    assert beat.frequency_hz == pytest.approx(frequency_hz, rel=1e-4)
    assert t[-1] - beat.end < 1.0 / frequency_hz


def test_noise_does_not_split_a_crossing():
    t = np.linspace(0, 3, 3001)
    signal = np.sin(2 * math.pi * t) + np.random.default_rng(1).normal(0, 0.05, t.size)
    crossings = upward_crossings(t, signal)
    np.testing.assert_allclose(np.diff(crossings), 1.0, atol=0.05)


def test_a_tail_at_rest_has_no_tail_beat():
    t = np.linspace(0, 3, 600)
    assert last_tail_beat(t, 1e-6 * np.sin(2 * math.pi * t), 1e-4) is None


def test_estimate_over_the_window_equals_the_ideal_estimate():
    t, angles, rates = stream(2.0)
    beat = last_tail_beat(t, tail_tip_lateral_positions(angles, G), 1e-4)
    windowed = estimate_speed_over(t, angles, rates, beat.start, beat.end, G)
    n = 512
    dt = 0.5 / n
    w = 4 * math.pi
    phases = w * np.arange(n)[:, None] * dt + np.array([0.0, -1.2])
    a = np.array([0.38, 0.47])
    ideal = estimate_speed(a * np.cos(phases), -a * w * np.sin(phases), dt, G)
    for field in ('speed', 'thrust', 'drag', 'swimming_number', 'tail_beat_hz',
                  'tail_tip_amplitude'):
        assert getattr(windowed, field) == pytest.approx(getattr(ideal, field), rel=2e-3)


def test_missing_rates_are_replaced_by_differences_of_the_angles():
    t, angles, rates = stream(2.0)
    beat = last_tail_beat(t, tail_tip_lateral_positions(angles, G), 1e-4)
    with_rates = estimate_speed_over(t, angles, rates, beat.start, beat.end, G)
    without = estimate_speed_over(t, angles, np.full_like(rates, np.nan), beat.start,
                                  beat.end, G)
    assert without.speed == pytest.approx(with_rates.speed, rel=2e-3)


@pytest.mark.parametrize('psi', [0.0, 1.0, -2.0])
def test_fundamental_phase_recovers_the_phase_of_a_sinusoid(psi):
    t = np.linspace(0, 3, 1500)
    signal = 0.02 + 0.05 * np.cos(2 * math.pi * 1.5 * t + psi)
    beat = last_tail_beat(t, signal, 1e-4)
    phase = fundamental_phase(t, signal, beat, t[-1])
    expected = 2 * math.pi * 1.5 * t[-1] + psi
    assert math.remainder(phase - expected, 2 * math.pi) == pytest.approx(0.0, abs=1e-3)


def test_history_keeps_only_its_span_and_refuses_old_stamps():
    history = ServoHistory(span_s=1.0)
    for i in range(300):
        assert history.add(1000 + i // 100, (i % 100) * 10_000_000, (0.0, 0.0), (0.0, 0.0))
    assert history.duration_s() == pytest.approx(1.0, abs=1e-9)
    assert not history.add(1002, 980_000_000, (1.0, 1.0), (0.0, 0.0))  # older than last
    times, angles, _ = history.arrays()
    assert angles[-1].tolist() == [0.0, 0.0] and np.all(np.diff(times) > 0)


def test_history_restarts_on_a_clock_jump_back():
    history = ServoHistory(span_s=1.0)
    history.add(1000, 0, (0.1, 0.2), (0.0, 0.0))
    history.add(1001, 0, (0.1, 0.2), (0.0, 0.0))
    assert history.add(5, 0, (0.3, 0.4), (0.0, 0.0))
    assert len(history) == 1 and history.stamp_of(0.0) == (5, 0)


def test_history_stamps_round_trip_with_nanosecond_resolution():
    history = ServoHistory(span_s=1.0)
    history.add(1_700_000_000, 123_456_789, (0.0, 0.0), (0.0, 0.0))
    times, _, _ = history.arrays()
    assert history.stamp_of(times[0]) == (1_700_000_000, 123_456_789)
