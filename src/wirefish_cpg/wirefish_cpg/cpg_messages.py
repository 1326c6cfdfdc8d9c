"""The CPG's parameters as a wirefish_msgs/CpgParams (message types only, no rclpy)."""

from __future__ import annotations

from wirefish_cpg.oscillator import CpgParameters
from wirefish_msgs.msg import CpgParams


def to_message(params: CpgParameters) -> CpgParams:
    """Return ``params`` as a wirefish_msgs/CpgParams (cpg_params, retune_gait's answer)."""
    return CpgParams(frequency_hz=params.frequency_hz, amplitude=list(params.amplitude),
                     offset=list(params.offset), w12=params.w12, w21=params.w21,
                     phi12=params.phi12, phi21=params.phi21, alpha=params.alpha)
