"""
The kinematics node's parameters as one table (no rclpy import), and the geometry block.

``GEOMETRY_PARAMETERS`` is the one declaration of the fish's dimensions as ROS parameters:
every node that needs geometry declares its fields from it (``geometry_parameters``), so
names, ranges and descriptions cannot drift apart. Defaults are ``FishGeometry()``'s and the
``wave_*`` defaults ``WaveSpec()``'s. Validation and declaration are the shared ones of
``wirefish_common.parameter_table``.
"""

from __future__ import annotations

from typing import Any, Mapping

from wirefish_common.parameter_table import (check_value, declare as declare_specs,
                                             merged_update, ParameterSpec, validate_update)
from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS
from wirefish_kinematics.wave_spec import WaveSpec

__all__ = ['BODY_WAVE_GEOMETRY_FIELDS', 'check_value', 'declare', 'GEOMETRY_PARAMETERS',
           'geometry_from', 'geometry_parameters', 'merged_update', 'NODE_PARAMETERS',
           'ParameterSpec', 'SPECS', 'validate_update', 'WAVE_PARAMETER_NAMES',
           'wave_from']


_DEFAULT = FishGeometry()
_GEOMETRY_DOC = {
    'l1': ('Length of flexible link L1, plate I to III (m); estimate', 1.0),
    'l2': ('Length of flexible link L2, plate III to V (m); estimate', 1.0),
    'l3': ('Length of the rigid caudal fin L3 (m); estimate', 1.0),
    'r1': ('Offset r1 of wire pair 1 from the body axis (m), eq 3; estimate', 1.0),
    'r2': ('Offset r2 of wire pair 2 from the body axis (m), eq 4; estimate', 1.0),
    'rd1': ('Radius R_D1 of reel 1 (m), eq 3; estimate', 1.0),
    'rd2': ('Radius R_D2 of reel 2 (m), eq 4; estimate', 1.0),
    'body_length': ('Body length L of Sw = U / (f L) (m); paper: 0.53', 10.0),
    'water_density': ('Water density rho (kg/m^3), eqs 16-18', 2000.0),
    'fin_span': ('Caudal fin span (m); A(L_T) = pi span^2 / 4, eq 16; estimate', 1.0),
    'wetted_area': ('Wetted surface area S_c (m^2), eq 17; estimate', 10.0),
    'drag_coefficient': ('Effective drag coefficient C_D, eq 17; calibrated '
                         '(python -m wirefish_analysis.calibrate_drag)', 10.0),
}
GEOMETRY_PARAMETERS = tuple(
    ParameterSpec(name, getattr(_DEFAULT, name), _GEOMETRY_DOC[name][0], 0.0,
                  _GEOMETRY_DOC[name][1], low_exclusive=True)
    for name in GEOMETRY_FIELDS)
# The fields the body wave (eqs 2-15) needs: enough for a node that only fits or draws it.
BODY_WAVE_GEOMETRY_FIELDS = ('l1', 'l2', 'l3', 'r1', 'r2', 'rd1', 'rd2')
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
NODE_PARAMETERS = GEOMETRY_PARAMETERS + WAVE_PARAMETERS + (
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
)
SPECS = {spec.name: spec for spec in NODE_PARAMETERS}


def markers_every(publish_rate_hz: float, markers_rate_hz: float) -> int:
    """
    Return n: body_wave_markers go out with every n-th body_wave (n >= 1).

    Markers cost more than the body wave itself (about 100 Points built in Python and
    converted), and a display needs far fewer than 50 a second; on a body_wave tick they show
    exactly that tick's shape.
    """
    return max(1, round(publish_rate_hz / markers_rate_hz))


def geometry_parameters(names: tuple[str, ...] = GEOMETRY_FIELDS) -> tuple[ParameterSpec, ...]:
    """Return the specs of the geometry fields ``names`` (all by default), in that order."""
    unknown = set(names) - set(GEOMETRY_FIELDS)
    if unknown:
        raise ValueError(f'not FishGeometry fields: {sorted(unknown)}')
    by_name = {spec.name: spec for spec in GEOMETRY_PARAMETERS}
    return tuple(by_name[name] for name in names)


def geometry_from(values: Mapping[str, Any], names: tuple[str, ...] = GEOMETRY_FIELDS
                  ) -> FishGeometry:
    """
    Return the FishGeometry of the fields ``names`` in a name -> value mapping.

    Fields outside ``names`` keep FishGeometry's defaults: a node declaring only
    ``BODY_WAVE_GEOMETRY_FIELDS`` never reads the others. Raises ``KeyError`` if a name is
    missing from ``values`` and ``ValueError`` if a value is invalid.
    """
    return FishGeometry(**{name: values[name] for name in names})


def wave_from(values: Mapping[str, Any]) -> WaveSpec:
    """Return the WaveSpec of the ``wave_*`` parameters in a name -> value mapping."""
    return WaveSpec(**{field: values[name] for name, field in WAVE_PARAMETER_NAMES.items()})


def declare(node, specs: tuple[ParameterSpec, ...] = NODE_PARAMETERS) -> None:
    """Declare the kinematics node's parameters (all of them by default) on ``node``."""
    combination = geometry_from if set(GEOMETRY_FIELDS) <= {s.name for s in specs} else None
    declare_specs(node, specs, combination)
