# SPDX-License-Identifier: Apache-2.0
"""The one wave type of eq 23 and its message converters."""

import math

import pytest
from wirefish_kinematics.wave_spec import wave_from_message, wave_message, WaveSpec
from wirefish_msgs.msg import BodyWaveSpec


def test_the_default_wave_is_the_section_5_2_case():
    assert WaveSpec() == WaveSpec(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0)


@pytest.mark.parametrize('kwargs, reason', [
    ({'c1': math.nan}, 'c1 must be finite'), ({'c2': math.inf}, 'c2 must be finite'),
    ({'k': 0.0}, 'k must be > 0'), ({'k': -1.0}, 'k must be > 0'),
    ({'frequency_hz': 0.0}, 'frequency_hz'), ({'frequency_hz': 10.5}, 'frequency_hz'),
])
def test_a_wave_eq_23_cannot_describe_is_refused_naming_the_field(kwargs, reason):
    with pytest.raises(ValueError, match=reason):
        WaveSpec(**kwargs)


def test_a_wave_survives_the_message_round_trip():
    wave = WaveSpec(c1=-0.05, c2=2.5, k=12.0, frequency_hz=3.0)
    assert wave_from_message(wave_message(wave)) == wave


def test_a_bad_message_is_refused_with_the_reason_of_the_type():
    with pytest.raises(ValueError, match='k must be > 0'):
        wave_from_message(BodyWaveSpec(c1=0.1, c2=1.0, k=0.0, frequency_hz=1.0))
