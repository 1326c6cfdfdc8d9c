# SPDX-License-Identifier: Apache-2.0
"""The CPG's parameters as a wirefish_msgs/CpgParams (message types only, no rclpy)."""

from __future__ import annotations

from wirefish_cpg.oscillator import CpgParameters
from wirefish_msgs.msg import CpgParams


def to_message(params: CpgParameters) -> CpgParams:
    """Return ``params`` as a wirefish_msgs/CpgParams (cpg_params, retune_gait's answer)."""
    return CpgParams(frequency_hz=params.frequency_hz, amplitude=list(params.amplitude),
                     offset=list(params.offset), w12=params.w12, w21=params.w21,
                     phi12=params.phi12, phi21=params.phi21, alpha=params.alpha)


def flat_message_values(msg: CpgParams) -> dict[str, float]:
    """
    Return a CpgParams' fields by the CPG's flat parameter names, unjudged (NaN stays NaN).

    The inverse of ``to_message`` on the flat names of ``cpg_node_parameters``: the CPG judges a
    cpg_command's values exactly as a parameter set of those names.
    """
    return {'frequency_hz': float(msg.frequency_hz),
            'amplitude_1': float(msg.amplitude[0]), 'amplitude_2': float(msg.amplitude[1]),
            'offset_1': float(msg.offset[0]), 'offset_2': float(msg.offset[1]),
            'w12': float(msg.w12), 'w21': float(msg.w21), 'phi12': float(msg.phi12),
            'phi21': float(msg.phi21), 'alpha': float(msg.alpha)}
