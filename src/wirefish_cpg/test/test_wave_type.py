"""The tuner fits the one wave type of the project (eq 23), not a copy of it."""

from wirefish_cpg.wave_loss import WaveSpec as FitWaveSpec
from wirefish_kinematics.wave_spec import WaveSpec


def test_the_fit_uses_the_kinematics_wave_type():
    assert FitWaveSpec is WaveSpec
