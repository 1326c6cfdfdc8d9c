# SPDX-License-Identifier: Apache-2.0
"""
Who sets the CPG's targets: the control topic or the node's parameters (pure; no rclpy).

The CPG has two sources of targets (eq 1's frequency, amplitudes, offsets, couplings, phase
biases and alpha). ``cpg_command`` is the control signal (the planner's, at its control rate);
the node's ROS parameters are its configuration and the manual override. The rule:

- At start-up the parameters are the targets, and the first valid command replaces them.
- A valid command sets the targets, unless a manual override is active.
- An accepted set of any eq 1 parameter after start-up (``ros2 param set``, a retune applied
  through ``set_parameters_atomically``) is a manual override: the parameters are the targets,
  and every command is refused, saying so, until ``follow_commands`` hands the targets back
  (the next command then applies).

A command is judged exactly as a parameter set is (``parameter_table.update_problem`` over the
same specs and the same combination check, ``CpgParameters``): ranges, NaN/inf, the servo
range of the amplitudes and offsets. A refused command changes nothing.
"""

from __future__ import annotations

from collections.abc import Mapping
import enum

from wirefish_common.parameter_table import ParameterSpec, update_problem
from wirefish_cpg.cpg_node_parameters import parameters_from
from wirefish_cpg.oscillator import CpgParameters


class TargetSource(enum.StrEnum):
    """Which input sets the targets (the values of wirefish_msgs/CpgStatus.source)."""

    COMMAND = 'command'
    MANUAL = 'manual'


MANUAL_REFUSAL = ('manual override: the parameters of {node} were set, so cpg_command is not '
                  'followed; call {node}/follow_commands (std_srvs/Trigger) to hand the '
                  'targets back')


class CpgTargets:
    """The targets the CPG runs, from its parameters and its commands, by the rule above."""

    def __init__(self, specs: Mapping[str, ParameterSpec], values: Mapping[str, object],
                 node_name: str = 'cpg_node') -> None:
        """Start from the node's parameter ``values`` (already judged), commands followed."""
        self._specs = dict(specs)
        self._node_name = node_name
        self.targets: CpgParameters = parameters_from(values)
        self.source = TargetSource.COMMAND
        self.refused = ''  # why the last command was refused ('' when it applied)

    def command(self, values: Mapping[str, object], commanded: Mapping[str, float]) -> bool:
        """
        Take a command's flat eq 1 values (``values``: the node's parameters now).

        Returns whether it applied; ``refused`` says why it did not ('' once one applies).
        """
        if self.source is TargetSource.MANUAL:
            self.refused = MANUAL_REFUSAL.format(node=self._node_name)
            return False
        reason = update_problem(self._specs, dict(values), list(commanded.items()),
                                parameters_from)
        if reason is not None:
            self.refused = f'cpg_command refused: {reason}'
            return False
        self.refused = ''
        self.targets = parameters_from({**values, **commanded})
        return True

    def parameters_set(self, values: Mapping[str, object]) -> None:
        """Take an accepted set of eq 1 parameters: they are the targets, a manual override."""
        self.targets = parameters_from(values)
        self.source = TargetSource.MANUAL

    def follow_commands(self) -> bool:
        """End a manual override (the targets stay until a command); return if one was on."""
        was_manual = self.source is TargetSource.MANUAL
        self.source = TargetSource.COMMAND
        self.refused = ''
        return was_manual
