# SPDX-License-Identifier: Apache-2.0
"""Fig 11 and Table 1 on the virtual fish: steady runs over frequency (no ROS, no pty)."""

import numpy as np
import pytest
from wirefish_analysis.fig11 import peak_frequency, run_steady, speed_sweep
from wirefish_cpg.table1_gait import table1_locked_at
from wirefish_kinematics.geometry import FishGeometry
from wirefish_sim.servo_model import ServoParameters
from wirefish_sim.virtual_fish import SimConfig


def test_table_1_gait_at_3_hz_swims_within_10_percent_of_eq_18():
    run = run_steady(table1_locked_at(3.0), 3.0, FishGeometry())
    print(f'3 Hz: virtual fish {run.speed:.4f} m/s, eq 18 {run.ideal_speed:.4f} m/s '
          f'({100 * (run.speed / run.ideal_speed - 1):+.1f} %)')
    assert run.speed == pytest.approx(run.ideal_speed, rel=0.10)


def test_speed_rises_then_falls_where_the_servo_cannot_follow(fig11_runs):
    speeds = [r.speed for r in fig11_runs]
    peak = int(np.argmax(speeds))
    assert fig11_runs[0].tail_tip_amplitude == pytest.approx(0.05, rel=0.02)
    assert all(b > a for a, b in zip(speeds[:peak], speeds[1:peak + 1]))
    assert all(b < a for a, b in zip(speeds[peak:], speeds[peak + 1:]))
    assert peak < len(speeds) - 2  # falls for at least two steps (1 Hz) before 8 Hz


def test_speed_peaks_between_5_and_7_5_hz_as_in_fig_11(fig11_runs):
    assert 5.0 <= peak_frequency(fig11_runs) <= 7.5


def test_tail_amplitude_falls_faster_above_5_hz(fig11_runs):
    amplitude = {r.frequency_hz: r.tail_tip_amplitude for r in fig11_runs}
    below = (amplitude[1.0] - amplitude[5.0]) / 4.0  # m per Hz
    above = (amplitude[5.0] - amplitude[8.0]) / 3.0
    print(f'tail amplitude loss: {100 * below:.2f} cm/Hz below 5 Hz, '
          f'{100 * above:.2f} cm/Hz above')
    assert above > 1.5 * below


def test_a_slower_servo_peaks_at_a_lower_frequency():
    frequencies = np.arange(4.0, 10.01, 1.0)

    def peak_hz(rate_limit: float) -> float:
        config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None,
                           servo=ServoParameters(rate_limit_rad_s=rate_limit))
        return peak_frequency(speed_sweep(frequencies, config=config))

    assert peak_hz(8.0) < peak_hz(12.0)
