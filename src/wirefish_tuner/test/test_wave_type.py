# SPDX-License-Identifier: Apache-2.0
"""The tuner fits the one wave type of the project (eq 23), not a copy of it."""

from wirefish_kinematics.wave_spec import WaveSpec
from wirefish_tuner.wave_loss import WaveSpec as FitWaveSpec


def test_the_fit_uses_the_kinematics_wave_type():
    assert FitWaveSpec is WaveSpec
