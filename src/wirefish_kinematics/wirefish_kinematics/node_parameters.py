"""
The kinematics node's parameters as one table, and their pure validation (no rclpy import).

``check_value`` runs in the node's ``add_on_set_parameters_callback``; ``declare`` builds each
``ParameterDescriptor`` with its description and ``FloatingPointRange``/``IntegerRange``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from wirefish_kinematics.geometry import FishGeometry, GEOMETRY_FIELDS


@dataclass(frozen=True)
class ParameterSpec:
    """A parameter: default (float, int or bool), description, inclusive range [low, high]."""

    name: str
    default: float | int | bool
    description: str
    low: float | None = None
    high: float | None = None
    low_exclusive: bool = False


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
                         '(python -m wirefish_bringup.calibrate_drag)', 10.0),
}
GEOMETRY_PARAMETERS = tuple(
    ParameterSpec(name, getattr(_DEFAULT, name), _GEOMETRY_DOC[name][0], 0.0,
                  _GEOMETRY_DOC[name][1], low_exclusive=True)
    for name in GEOMETRY_FIELDS)
WAVE_PARAMETERS = (
    ParameterSpec('wave_c1', 0.15, 'Desired wave envelope c1 (m/m), eq 23; used until a '
                  'target_wave arrives, and again after any wave_* change', -10.0, 10.0),
    ParameterSpec('wave_c2', 1.0, 'Desired wave envelope c2 (1/m), eq 23', -100.0, 100.0),
    ParameterSpec('wave_k', 8.0, 'Desired wave number k (rad/m), eq 23', 0.0, 100.0,
                  low_exclusive=True),
    ParameterSpec('wave_frequency_hz', 1.0, 'Desired wave frequency (Hz), eq 23', 0.0, 10.0,
                  low_exclusive=True),
)
NODE_PARAMETERS = GEOMETRY_PARAMETERS + WAVE_PARAMETERS + (
    ParameterSpec('station_count', 50, 'Stations along the tail in body_wave', 2, 1000),
    ParameterSpec('publish_rate_hz', 50.0, 'Rate of body_wave and body_wave_markers (Hz)',
                  0.1, 500.0),
    ParameterSpec('use_servo_state', False,
                  'Read the measured servo_state (bridge) instead of the commanded servo_cmd'),
    ParameterSpec('max_tail_beat_period_s', 2.5,
                  'Longest tail-beat period detected (s); samples of twice this are kept',
                  0.1, 20.0),
)
SPECS = {spec.name: spec for spec in NODE_PARAMETERS}


def check_value(spec: ParameterSpec, value: object) -> str | None:
    """Return why ``value`` is not acceptable for ``spec``, or None if it is."""
    kind = type(spec.default)
    if kind is bool:
        return None if type(value) is bool else f'{spec.name} must be a bool, got {value!r}'
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f'{spec.name} must be a number, got {value!r}'
    if kind is int and not isinstance(value, int):
        return f'{spec.name} must be an integer, got {value!r}'
    if not math.isfinite(value):
        return f'{spec.name} must be finite, got {value}'
    if spec.low is not None:
        if spec.low_exclusive and value <= spec.low:
            return f'{spec.name} must be > {spec.low:g}, got {value:g}'
        if value < spec.low:
            return f'{spec.name} must be >= {spec.low:g}, got {value:g}'
    if spec.high is not None and value > spec.high:
        return f'{spec.name} must be <= {spec.high:g}, got {value:g}'
    return None


def geometry_from(values: dict[str, object]) -> FishGeometry:
    """Return the FishGeometry of a name -> value mapping (raises ValueError if invalid)."""
    return FishGeometry(**{name: values[name] for name in GEOMETRY_FIELDS})


def declare(node, specs: tuple[ParameterSpec, ...] = NODE_PARAMETERS) -> None:
    """Declare every spec on ``node`` with a descriptor carrying its description and range."""
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

    for spec in specs:
        descriptor = ParameterDescriptor(description=spec.description)
        if spec.low is not None and spec.high is not None:
            if type(spec.default) is float:
                descriptor.floating_point_range = [FloatingPointRange(
                    from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
            elif type(spec.default) is int:
                descriptor.integer_range = [IntegerRange(
                    from_value=int(spec.low), to_value=int(spec.high), step=1)]
        if spec.low_exclusive:
            descriptor.additional_constraints = f'> {spec.low:g}'
        node.declare_parameter(spec.name, spec.default, descriptor)
