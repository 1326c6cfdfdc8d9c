# SPDX-License-Identifier: Apache-2.0
"""The C_D calibration command (wirefish_analysis.calibrate_drag) and the paper's figures."""

from dataclasses import replace
import subprocess
import sys

import numpy as np
import pytest
from wirefish_analysis.calibrate_drag import (calibrated_drag_coefficient, least_squares_drag,
                                              PAPER_POINTS, point_means, predict)
from wirefish_cpg.table1_gait import amplitude_scale_for, table1_locked_at, tip_half_amplitude
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import steady_speed


def test_calibration_reproduces_the_default_drag_coefficient():
    assert calibrated_drag_coefficient() == pytest.approx(FishGeometry().drag_coefficient,
                                                          abs=1e-6)


def test_calibration_does_not_depend_on_the_drag_coefficient_it_starts_from():
    assert calibrated_drag_coefficient(FishGeometry(drag_coefficient=5.0)) == pytest.approx(
        calibrated_drag_coefficient(), rel=1e-12)


def test_calibrated_model_gives_the_paper_speed_at_3_hz():
    calibration = predict(PAPER_POINTS[0], FishGeometry())
    assert calibration.estimate.speed == pytest.approx(0.39, rel=1e-9)
    assert calibration.estimate.tail_beat_hz == pytest.approx(3.0, rel=1e-12)


def test_table1_tail_tip_half_amplitude_at_1_hz_is_4_to_9_cm():
    amplitude = tip_half_amplitude(table1_locked_at(1.0), FishGeometry())
    assert 0.04 <= amplitude <= 0.09


@pytest.mark.parametrize('point', PAPER_POINTS[1:], ids=lambda p: p.label)
def test_paper_points_are_evaluated_at_the_stated_tip_amplitude_and_frequency(point):
    prediction = predict(point, FishGeometry())
    assert prediction.estimate.tail_tip_amplitude == pytest.approx(point.tip_amplitude,
                                                                   rel=1e-9)
    assert prediction.estimate.tail_beat_hz == pytest.approx(point.frequency_hz, rel=1e-12)


def test_the_command_prints_the_calibration_and_the_paper_points():
    result = subprocess.run([sys.executable, '-m', 'wirefish_analysis.calibrate_drag',
                             '--no-virtual-fish'], capture_output=True, text=True, check=True)
    assert f'calibrated C_D = {FishGeometry().drag_coefficient:.9f}' in result.stdout
    assert 'differs' not in result.stdout
    for point in PAPER_POINTS:
        assert point.label in result.stdout
    fit = least_squares_drag()
    assert f'C_D = {fit.drag_coefficient:.6f}, speed RMSE {fit.rmse:.4f} m/s' in result.stdout
    assert 'eq 18 cannot fit' in result.stdout


@pytest.fixture(scope='module')
def least_squares():
    return least_squares_drag()


def _sum_of_squares(c_d):
    geometry = replace(FishGeometry(), drag_coefficient=c_d)
    means = np.array([point_means(p, geometry) for p in PAPER_POINTS])
    speeds = steady_speed(means[:, 0], means[:, 1], geometry)
    return float(np.sum((speeds - [p.paper_speed for p in PAPER_POINTS]) ** 2))


@pytest.mark.parametrize('factor', [0.99, 1.01])
def test_least_squares_drag_is_the_minimum_of_the_speed_misses(least_squares, factor):
    best = least_squares.drag_coefficient
    assert _sum_of_squares(best * factor) > _sum_of_squares(best)


def test_least_squares_rmse_is_no_worse_than_the_one_point_calibration(least_squares):
    one_point = np.sqrt(_sum_of_squares(FishGeometry().drag_coefficient) / len(PAPER_POINTS))
    assert least_squares.rmse <= one_point
    assert least_squares.rmse == pytest.approx(
        np.sqrt(_sum_of_squares(least_squares.drag_coefficient) / len(PAPER_POINTS)), rel=1e-9)


def test_eq18_swimming_number_does_not_depend_on_frequency_for_one_tail_shape():
    slow, fast = (replace(PAPER_POINTS[1], frequency_hz=f) for f in (1.0, 6.5))
    sw = [float(steady_speed(*point_means(p, FishGeometry()), FishGeometry())) / p.frequency_hz
          for p in (slow, fast)]
    assert sw[0] == pytest.approx(sw[1], rel=1e-6)


def test_an_unreachable_tip_amplitude_is_refused_with_its_reach():
    with pytest.raises(ValueError, match='out of reach'):
        amplitude_scale_for(0.5, 1.0, FishGeometry())
