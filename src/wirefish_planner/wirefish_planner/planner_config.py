# SPDX-License-Identifier: Apache-2.0
"""
What the planner node builds from its parameters (pure; no rclpy at import).

``planner_from(values)`` is both the validation of a parameter set (its ``ValueError`` is the
reason an update is refused) and the construction of the ``Planner``; ``cpg_values`` turns a
planner output into the CPG targets it asks for, ``command_targets`` into a whole cpg_command.
The table itself is ``planner_node_parameters``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from wirefish_cpg.cpg_node_parameters import CPG_PARAMETER_NAMES
from wirefish_kinematics.geometry_parameters import BODY_WAVE_GEOMETRY_FIELDS, geometry_from
from wirefish_kinematics.wave_spec import WaveSpec
from wirefish_planner.gait_choice import (GaitFamily, GaitLimits, GaitPlanner, library_family,
                                          Table1Family)
from wirefish_planner.planner_core import Planner, PlannerOutput, PlannerSettings
from wirefish_planner.yaw_control import YawGains

GAIT_SOURCES = ('table1', 'library')
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
