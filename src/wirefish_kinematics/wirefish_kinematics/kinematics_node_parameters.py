# SPDX-License-Identifier: Apache-2.0
"""
The kinematics node's parameters as one table (no rclpy import).

The geometry comes from the graph's one geometry block (``geometry_parameters``); the
``wave_*`` defaults are ``WaveSpec()``'s. ``RULE``: the values make a ``FishGeometry``.
Validation and declaration are the shared ones of ``wirefish_common.parameter_table``.
"""

from __future__ import annotations

from typing import Any, Mapping

from wirefish_common.parameter_table import builds, ParameterSpec, ParameterTable, Rule
from wirefish_kinematics.geometry_parameters import geometry_from, GEOMETRY_PARAMETERS
from wirefish_kinematics.wave_spec import WaveSpec

_WAVE = WaveSpec()
# wave_<field> parameter -> WaveSpec field
WAVE_PARAMETER_NAMES = {'wave_c1': 'c1', 'wave_c2': 'c2', 'wave_k': 'k',
                        'wave_frequency_hz': 'frequency_hz'}
WAVE_PARAMETERS = (
    ParameterSpec('wave_c1', _WAVE.c1, 'Desired wave envelope c1 (m/m), eq 23; used until a '
                  'target_wave arrives, and again after any wave_* change', -10.0, 10.0),
    ParameterSpec('wave_c2', _WAVE.c2, 'Desired wave envelope c2 (1/m), eq 23', -100.0, 100.0),
    ParameterSpec('wave_k', _WAVE.k, 'Desired wave number k (rad/m), eq 23', 0.0, 100.0,
                  low_exclusive=True),
    ParameterSpec('wave_frequency_hz', _WAVE.frequency_hz, 'Desired wave frequency (Hz), eq 23',
                  0.0, 10.0, low_exclusive=True),
)
RULE: Rule = builds(geometry_from)
TABLE = ParameterTable(GEOMETRY_PARAMETERS + WAVE_PARAMETERS + (
    ParameterSpec('station_count', 50, 'Stations along the tail in body_wave', 2, 1000),
    ParameterSpec('publish_rate_hz', 50.0, 'Rate of body_wave (Hz)', 0.1, 500.0),
    ParameterSpec('markers_rate_hz', 10.0,
                  'Rate of body_wave_markers (Hz): every n-th body_wave, n = '
                  'round(publish_rate_hz / markers_rate_hz), at least 1', 0.1, 500.0),
    ParameterSpec('use_servo_state', False,
                  'Read the measured servo_state (bridge) instead of the commanded servo_cmd'),
    ParameterSpec('max_tail_beat_period_s', 2.5,
                  'Longest tail-beat period detected (s); samples of twice this are kept',
                  0.1, 20.0),
), RULE)


def markers_every(publish_rate_hz: float, markers_rate_hz: float) -> int:
    """
    Return n: body_wave_markers go out with every n-th body_wave (n >= 1).

    Markers cost more than the body wave itself (about 100 Points built in Python and
    converted), and a display needs far fewer than 50 a second; on a body_wave tick they show
    exactly that tick's shape.
    """
    return max(1, round(publish_rate_hz / markers_rate_hz))


def wave_from(values: Mapping[str, Any]) -> WaveSpec:
    """Return the WaveSpec of the ``wave_*`` parameters in a name -> value mapping."""
    return WaveSpec(**{field: values[name] for name, field in WAVE_PARAMETER_NAMES.items()})
