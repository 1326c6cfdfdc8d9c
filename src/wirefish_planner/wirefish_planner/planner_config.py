"""
The planner node's parameter table and what it builds (pure; no rclpy at import).

``planner_from(values)`` is both the validation of a parameter set (its ``ValueError`` is the
reason an update is refused) and the construction of the ``Planner``; ``cpg_values`` turns a
planner output into the CPG targets it asks for, ``command_targets`` into a whole cpg_command.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

from wirefish_common.parameter_table import ParameterSpec
from wirefish_cpg.cpg_parameter_names import CPG_PARAMETER_NAMES
from wirefish_cpg.gait_library import default_library_path
from wirefish_kinematics.node_parameters import (BODY_WAVE_GEOMETRY_FIELDS, geometry_from,
                                                 geometry_parameters)
from wirefish_kinematics.wave_spec import WaveSpec
from wirefish_planner.gait_family import (GaitFamily, GaitLimits, GaitPlanner, library_family,
                                          Table1Family)
from wirefish_planner.planner_core import Planner, PlannerOutput, PlannerSettings
from wirefish_planner.yaw_control import YawGains

HALF_PI = math.pi / 2
_LIMITS, _GAINS, _WAVE = GaitLimits(), YawGains(), WaveSpec()
GAIT_SOURCES = ('table1', 'library')
PLANNER_PARAMETERS = (
    ParameterSpec('cpg_node_name', 'cpg_node',
                  'Name (relative or absolute) of the CPG node the planner drives'),
    ParameterSpec('cmd_vel_timeout_s', 0.5,
                  'Rest (speed 0, hold released) after this long without cmd_vel (s)', 0.0,
                  60.0, low_exclusive=True),
    ParameterSpec('imu_timeout_s', 0.5,
                  'Turn open loop (feed-forward only) after this long without imu/data (s)',
                  0.0, 60.0, low_exclusive=True),
    ParameterSpec('control_rate_hz', 20.0, 'Rate of cpg_command and planner_state (Hz)', 1.0,
                  200.0),
    ParameterSpec('min_frequency_hz', _LIMITS.min_frequency_hz,
                  'Lowest tail-beat frequency of a gait (Hz)', 0.0, 10.0, low_exclusive=True),
    ParameterSpec('max_frequency_hz', _LIMITS.max_frequency_hz,
                  'Highest tail-beat frequency of a gait (Hz)', 0.0, 10.0, low_exclusive=True),
    ParameterSpec('max_amplitude_scale', _LIMITS.max_amplitude_scale,
                  "Largest factor on Table 1's R_i (1: tail tip ~8.8 cm)", 0.0, 3.3,
                  low_exclusive=True),
    ParameterSpec('servo_rate_limit_rad_s', _LIMITS.servo_rate_limit_rad_s,
                  "Servo slew limit (rad/s); the virtual fish's is 9.1", 0.0, 100.0,
                  low_exclusive=True),
    ParameterSpec('slew_margin', _LIMITS.slew_margin,
                  'Fraction of the slew limit a gait may use', 0.0, 1.0, low_exclusive=True),
    ParameterSpec('servo_limit_rad', _LIMITS.servo_limit_rad, 'Servo angle range (+-rad)', 0.0,
                  math.pi, low_exclusive=True),
    ParameterSpec('max_offset_rad', _LIMITS.max_offset_rad,
                  'Largest turning offset b (rad); output limit of the yaw PI', 0.0, HALF_PI,
                  low_exclusive=True),
    ParameterSpec('turn_gain', _GAINS.turn_gain,
                  'Feed-forward k of r = k U b (rad/s per rad of offset per m/s; < 0: a tail '
                  'held right turns right)', -100.0, 100.0),
    ParameterSpec('yaw_rate_kp', _GAINS.kp, 'Proportional gain of the yaw-rate PI (1)', 0.0,
                  20.0),
    ParameterSpec('yaw_rate_ki', _GAINS.ki, 'Integral gain of the yaw-rate PI (1/s)', 0.0,
                  20.0),
    ParameterSpec('yaw_rate_integral_limit', _GAINS.integral_limit,
                  'Anti-windup: largest yaw rate the integrator may add (rad/s)', 0.0, 5.0),
    ParameterSpec('heading_gain', _GAINS.heading_gain,
                  'Heading hold: yaw-rate reference per rad of heading error (1/s)', 0.0, 20.0),
    ParameterSpec('max_hold_rate', _GAINS.max_hold_rate,
                  'Heading hold: largest yaw-rate reference (rad/s)', 0.0, 5.0),
    ParameterSpec('heading_hold', True,
                  'angular.z = 0 holds the heading the turn ended on (else yaw rate 0)'),
    ParameterSpec('yaw_control', True,
                  'Close the yaw loops on imu/data (false: feed-forward offsets only)'),
    ParameterSpec('gait_source', 'table1',
                  "Gait family: 'table1' (Table 1 locked at f, R_i scaled) or 'library' (the "
                  "gait library's fits of the reference wave, blended inside their grid; Table "
                  '1 while the library has no such family)'),
    ParameterSpec('library_path', str(default_library_path()),
                  "Gait library file (tuner_node's library_path); read at start-up and on any "
                  'parameter change'),
    ParameterSpec('reference_wave_c1', _WAVE.c1,
                  "Library family's reference wave c1 (m/m), eq 23; scaled by s", -10.0, 10.0),
    ParameterSpec('reference_wave_c2', _WAVE.c2,
                  "Library family's reference wave c2 (1/m), eq 23; scaled by s", -100.0,
                  100.0),
    ParameterSpec('reference_wave_k', _WAVE.k, "Library family's reference wave k (rad/m)", 0.0,
                  100.0, low_exclusive=True),
    ParameterSpec('rest_at_start', True,
                  'Rest the CPG at start-up (no cmd_vel yet: the fish rests); false: leave '
                  'cpg_node as it is until the first cmd_vel'),
) + geometry_parameters()  # eq 18 needs the fish's geometry: the graph's one /** block
GAIT_NAMES = ('frequency_hz', 'amplitude_1', 'amplitude_2', 'w12', 'w21', 'phi12', 'phi21',
              'alpha')
OFFSET_NAMES = ('offset_1', 'offset_2')
OFFSET_DEADBAND_RAD = 0.002  # smaller offset changes are not sent (the CPG would barely move)


def planner_from(values: Mapping[str, Any], family: GaitFamily | None = None) -> Planner:
    """
    Return the Planner of a parameter set; raise ValueError naming what is inconsistent.

    Values are typed Any: the parameter table has judged their types, the dataclasses judge
    their values.
    """
    limits = GaitLimits(
        min_frequency_hz=values['min_frequency_hz'], max_frequency_hz=values['max_frequency_hz'],
        max_amplitude_scale=values['max_amplitude_scale'],
        servo_rate_limit_rad_s=values['servo_rate_limit_rad_s'],
        slew_margin=values['slew_margin'], servo_limit_rad=values['servo_limit_rad'],
        max_offset_rad=values['max_offset_rad'])
    gains = YawGains(turn_gain=values['turn_gain'], kp=values['yaw_rate_kp'],
                     ki=values['yaw_rate_ki'], max_offset_rad=values['max_offset_rad'],
                     integral_limit=values['yaw_rate_integral_limit'],
                     heading_gain=values['heading_gain'], max_hold_rate=values['max_hold_rate'])
    settings = PlannerSettings(cmd_vel_timeout_s=values['cmd_vel_timeout_s'],
                               imu_timeout_s=values['imu_timeout_s'],
                               heading_hold=values['heading_hold'],
                               yaw_control=values['yaw_control'])
    geometry = geometry_from(values)
    note = ''
    if family is None:
        family, note = gait_family_from(values)
    return Planner(GaitPlanner(family, limits, geometry, note), gains, settings)


def gait_family_from(values: Mapping[str, Any]) -> tuple[GaitFamily, str]:
    """
    Return the gait family the parameters ask for, and why it is not that one ('' if it is).

    The library family needs a 2 x 2 grid of fits of the reference wave on this geometry;
    until the library has one, Table 1's family is used and the note says why.
    """
    source = values['gait_source']
    if source not in GAIT_SOURCES:
        raise ValueError(f'gait_source must be one of {GAIT_SOURCES}, got {source!r}')
    if source == 'table1':
        return Table1Family(), ''
    reference = WaveSpec(values['reference_wave_c1'], values['reference_wave_c2'],
                         values['reference_wave_k'], 1.0)
    body = {name: float(values[name]) for name in BODY_WAVE_GEOMETRY_FIELDS}
    try:
        return library_family(Path(values['library_path']), reference, body), ''
    except ValueError as error:
        return Table1Family(), f'gait library not used ({error}); Table 1 family'


def default_values() -> dict[str, Any]:
    """Return the parameters' defaults by name."""
    return {spec.name: spec.default for spec in PLANNER_PARAMETERS}


def cpg_values(out: PlannerOutput) -> dict[str, float]:
    """
    Return the cpg_node parameters of ``out``: the gait with b_1 = b_2 = offset, or rest.

    At rest only the amplitudes and offsets are set (to 0): the CPG's convergence brings the
    tail to rest, and the frequency and coupling stay as they were.
    """
    point = out.gait.point
    if point is None:
        return {'amplitude_1': 0.0, 'amplitude_2': 0.0, 'offset_1': 0.0, 'offset_2': 0.0}
    p = point.params
    values = dict(zip(GAIT_NAMES, (p.frequency_hz, *p.amplitude, p.w12, p.w21, p.phi12,
                                   p.phi21, p.alpha)))
    values.update({name: float(out.offset) for name in OFFSET_NAMES})
    return {name: float(value) for name, value in values.items()}


def command_targets(wanted: dict[str, float], running: dict[str, float] | None
                    ) -> dict[str, float] | None:
    """
    Return the whole target set of a cpg_command: ``wanted`` over what the CPG ``running``.

    A gait names every target; rest names only amplitudes and offsets, and keeps the frequency
    and couplings the CPG runs (None while that is not known: no command yet).
    """
    if set(wanted) >= set(CPG_PARAMETER_NAMES):
        return {name: wanted[name] for name in CPG_PARAMETER_NAMES}
    if running is None:
        return None
    return {name: float(wanted.get(name, running[name])) for name in CPG_PARAMETER_NAMES}


def cpg_topic(cpg_node_name: str, topic: str) -> str:
    """Return ``topic`` in the namespace of the node ``cpg_node_name`` (relative or not)."""
    namespace, _, _ = cpg_node_name.rpartition('/')
    if not namespace:
        return f'/{topic}' if cpg_node_name.startswith('/') else topic
    return f'{namespace}/{topic}'


def values_changed(sent: dict[str, float] | None, wanted: dict[str, float]) -> bool:
    """Return whether ``wanted`` differs from what cpg_node last accepted (offset deadband)."""
    if sent is None:
        return True
    for name, value in wanted.items():
        if name not in sent:
            return True
        tolerance = OFFSET_DEADBAND_RAD if name in OFFSET_NAMES and value != 0.0 else 0.0
        if abs(sent[name] - value) > tolerance:
            return True
    return False
