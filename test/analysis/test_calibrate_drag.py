"""The C_D calibration command (wirefish_analysis.calibrate_drag) and the paper's figures."""

import subprocess
import sys

import pytest
from wirefish_analysis.calibrate_drag import calibrated_drag_coefficient, PAPER_POINTS, predict
from wirefish_cpg.table1_gait import table1_locked_at, tip_half_amplitude
from wirefish_kinematics.geometry import FishGeometry


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
    result = subprocess.run([sys.executable, '-m', 'wirefish_analysis.calibrate_drag'],
                            capture_output=True, text=True, check=True)
    assert f'calibrated C_D = {FishGeometry().drag_coefficient:.9f}' in result.stdout
    assert 'differs' not in result.stdout
    for point in PAPER_POINTS:
        assert point.label in result.stdout
