# SPDX-License-Identifier: Apache-2.0
"""
The cpg node's parameters as one table (no rclpy import), and their one mapping to eq 1.

ROS parameters are flat scalars, so the pairs (R_1, R_2) and (B_1, B_2) of ``CpgParameters``
become ``amplitude_1``/``amplitude_2`` and ``offset_1``/``offset_2``; the scalars keep their
field names. ``flat_values`` and ``parameters_from`` are the one mapping between the two (the
latter also the rule of the parameters' combination). ``CPG_PARAMETERS`` gives each flat name
its range and description; its defaults are those of ``CpgParameters()`` (Table 1 of the paper,
v = 1 Hz, alpha = 20, b = 0), written only there. The node's ``TABLE`` adds what drives its
publish loop; its ``RULE`` is that the values make a ``CpgParameters``. Validation and
declaration are the shared ones of ``wirefish_common.parameter_table``; the cpg node, the
tuner, the planner and pure tests share this module.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

from wirefish_common.parameter_table import builds, ParameterSpec, ParameterTable, Rule
from wirefish_cpg.oscillator import CpgParameters

HALF_PI = math.pi / 2
# flat name -> (CpgParameters field, index into the field's pair, or None for a scalar)
_FIELD_OF = {
    'frequency_hz': ('frequency_hz', None),
    'amplitude_1': ('amplitude', 0),
    'amplitude_2': ('amplitude', 1),
    'offset_1': ('offset', 0),
    'offset_2': ('offset', 1),
    'w12': ('w12', None),
    'w21': ('w21', None),
    'phi12': ('phi12', None),
    'phi21': ('phi21', None),
    'alpha': ('alpha', None),
}
CPG_PARAMETER_NAMES = tuple(_FIELD_OF)


def flat_values(params: CpgParameters) -> dict[str, float]:
    """Return ``params`` as flat name -> value, in ``CPG_PARAMETER_NAMES`` order."""
    values = {}
    for name, (field, index) in _FIELD_OF.items():
        value = getattr(params, field)
        values[name] = float(value if index is None else value[index])
    return values


def parameters_from(values: Mapping[str, Any]) -> CpgParameters:
    """
    Return the CpgParameters of a flat name -> value mapping (e.g. the node's parameters).

    Raises ``KeyError`` if a name of ``CPG_PARAMETER_NAMES`` is missing and ``ValueError`` if
    the values are not a valid network (``CpgParameters`` says why).
    """
    fields: dict[str, Any] = {}
    pairs: dict[str, list[Any]] = {}
    for name, (field, index) in _FIELD_OF.items():
        if index is None:
            fields[field] = values[name]
        else:
            pairs.setdefault(field, [None, None])[index] = values[name]
    fields.update((field, tuple(pair)) for field, pair in pairs.items())
    return CpgParameters(**fields)


_DEFAULT = flat_values(CpgParameters())
_SPEC_OF = {
    'frequency_hz': ('Intrinsic oscillator frequency v (Hz), eq 1', 0.0, 10.0, True),
    'amplitude_1': ('Target amplitude R_1 of servo 1 (rad)', -HALF_PI, HALF_PI, False),
    'amplitude_2': ('Target amplitude R_2 of servo 2 (rad)', -HALF_PI, HALF_PI, False),
    'offset_1': ('Target offset b_1 of servo 1 (rad); turning', -HALF_PI, HALF_PI, False),
    'offset_2': ('Target offset b_2 of servo 2 (rad); turning', -HALF_PI, HALF_PI, False),
    'w12': ('Coupling weight omega_12 of oscillator 2 on 1 (1/s)', -10.0, 10.0, False),
    'w21': ('Coupling weight omega_21 of oscillator 1 on 2 (1/s)', -10.0, 10.0, False),
    'phi12': ('Phase bias phi_12 (rad)', -math.pi, math.pi, False),
    'phi21': ('Phase bias phi_21 (rad)', -math.pi, math.pi, False),
    'alpha': ('Convergence gain alpha of amplitude and offset (1/s)', 0.0, 200.0, True),
}
CPG_PARAMETERS = tuple(
    ParameterSpec(name, _DEFAULT[name], description, low, high, low_exclusive=exclusive)
    for name, (description, low, high, exclusive) in _SPEC_OF.items())
RULE: Rule = builds(parameters_from)
TABLE = ParameterTable(CPG_PARAMETERS + (
    # The default is the rate the fish receives: the bridge forwards at most its
    # max_command_rate_hz (100 Hz) to the board, so a faster stream is paid for by every
    # subscriber and then dropped at the gate. eq 1 is integrated at integration_step_s
    # whatever the publish rate, so the output at a publish instant does not depend on it.
    ParameterSpec('publish_rate_hz', 100.0,
                  'Rate of servo_cmd (Hz); the default is the rate the bridge forwards to the '
                  'board', 1.0, 1000.0),
    ParameterSpec('integration_step_s', 0.001,
                  'Fixed RK4 step of eq 1 (s), independent of the publish rate', 1e-5, 0.01),
    ParameterSpec('servo_limit_rad', math.pi / 2, 'Servo angle limit; outputs are clamped (rad)',
                  0.0, math.pi, low_exclusive=True),
    ParameterSpec('autostart', True, 'Start oscillating at launch (else wait for start)'),
), RULE)
