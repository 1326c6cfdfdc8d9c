# SPDX-License-Identifier: Apache-2.0
"""Who sets the CPG's targets (cpg_control): commands judged as parameters, the manual rule."""

import math

import numpy as np
import pytest
from wirefish_common.parameter_table import update_problem
from wirefish_cpg.cpg_control import CpgTargets, TargetSource
from wirefish_cpg.cpg_node_parameters import flat_values, parameters_from, TABLE
from wirefish_cpg.oscillator import CpgIntegrator, CpgParameters
from wirefish_cpg.table1_gait import table1_locked_at

VALUES = TABLE.defaults()
SPECS = TABLE.by_name
TURNING = CpgParameters(frequency_hz=1.5, amplitude=(0.3, 0.4), offset=(0.1, 0.1))
# The planner drive test's smoothness bound on servo_cmd (test/planner/test_planner_graph.py):
# between two samples no more than the larger reported rate allows plus the CPG's largest
# acceleration, 300 rad/s^2.
MAX_CPG_ACCELERATION = 300.0
COMMAND_PERIOD_S = 0.05  # the planner's 20 Hz
SERVO_PERIOD_S = 0.005  # cpg_node's 200 Hz


def _targets() -> CpgTargets:
    return CpgTargets(SPECS, VALUES, '/fish/cpg_node')


def test_a_valid_command_sets_the_targets():
    control = _targets()
    assert control.command(VALUES, flat_values(TURNING))
    assert control.targets == TURNING and control.refused == ''


@pytest.mark.parametrize('name, value', [
    ('frequency_hz', math.nan), ('frequency_hz', 0.0), ('amplitude_1', math.inf),
    ('amplitude_2', 2.0), ('offset_1', -1.6), ('alpha', 0.0), ('phi12', 3.5)])
def test_a_command_is_judged_as_a_parameter_set_and_a_refused_one_changes_nothing(name, value):
    control = _targets()
    before = control.targets
    commanded = dict(flat_values(TURNING), **{name: value})
    assert not control.command(VALUES, commanded)
    reason = update_problem(SPECS, VALUES, list(commanded.items()), parameters_from)
    assert reason is not None and control.refused == f'cpg_command refused: {reason}'
    assert control.targets == before


def test_a_parameter_set_overrides_commands_until_follow_commands():
    control = _targets()
    control.command(VALUES, flat_values(TURNING))
    fitted = dict(VALUES, frequency_hz=1.2, amplitude_1=0.2)
    control.parameters_set(fitted)
    assert control.source is TargetSource.MANUAL
    assert control.targets == parameters_from(fitted)
    assert not control.command(VALUES, flat_values(TURNING))  # the planner does not win
    assert 'manual override' in control.refused and '/fish/cpg_node/follow_commands' in \
        control.refused
    assert control.targets == parameters_from(fitted)
    assert control.follow_commands() and control.source is TargetSource.COMMAND
    assert control.targets == parameters_from(fitted)  # handing back changes nothing yet
    assert control.command(VALUES, flat_values(TURNING)) and control.targets == TURNING
    assert not control.follow_commands()  # not under an override any more


def _planner_like_gaits() -> list[CpgParameters]:
    """Return gaits as the planner's Table 1 family makes them, 1-2 Hz at 0.6-1.0 x R_i."""
    return [table1_locked_at(f, s) for f in np.linspace(1.0, 2.0, 6) for s in (0.6, 0.8, 1.0)]


def test_commands_with_random_drops_are_followed_and_the_servo_output_never_steps():
    """10,000 commands at 20 Hz, 30 % lost: the targets are the latest received, no step."""
    rng = np.random.default_rng(24)
    gaits = _planner_like_gaits()
    control = _targets()
    cpg = CpgIntegrator(control.targets, step_s=VALUES['integration_step_s'])
    samples = []  # (t, angle 1, angle 2, rate 1, rate 2) at the servo rate
    received = 0
    t = 0.0
    for _ in range(10_000):
        gait = gaits[rng.integers(len(gaits))]
        offset = float(rng.uniform(-0.15, 0.15))
        commanded = dict(flat_values(gait), offset_1=offset, offset_2=offset)
        if rng.random() >= 0.3:  # delivered
            received += 1
            assert control.command(VALUES, commanded)
            cpg.set_parameters(control.targets)
            assert cpg.parameters == control.targets == parameters_from(commanded)
        for _ in range(round(COMMAND_PERIOD_S / SERVO_PERIOD_S)):
            t += SERVO_PERIOD_S
            cpg.advance(t)
            angles, rates = cpg.output(t)
            samples.append((t, *angles, *rates))
    servo = np.array(samples)
    dt = np.diff(servo[:, 0])
    steps = np.abs(np.diff(servo[:, 1:3], axis=0))
    bound = np.maximum(np.abs(servo[:-1, 3:5]), np.abs(servo[1:, 3:5])) * dt[:, None] \
        + 0.5 * MAX_CPG_ACCELERATION * dt[:, None] ** 2 + 1e-3
    print(f'{received} of 10000 commands received; largest servo change per sample '
          f'{steps.max():.4f} rad, largest excess over the smooth bound '
          f'{(steps - bound).max():.5f} rad')
    assert 6_500 <= received <= 7_500
    assert float((steps - bound).max()) <= 0.0
