# SPDX-License-Identifier: Apache-2.0
"""The servo limit applied to the CPG's output before it becomes a command."""

from __future__ import annotations

from collections.abc import Sequence

ServoPair = tuple[float, float]


def clamp_to_limit(angles: Sequence[float], rates: Sequence[float], limit_rad: float
                   ) -> tuple[ServoPair, ServoPair, bool]:
    """
    Return (angles clipped to [-limit, limit] rad, rates, whether any angle was clipped).

    A clipped servo holds still at the limit, so its rate is 0 (rad/s): a consumer integrating
    the rate must not run past the angle. Two servos, plain floats (called at every CPG tick).
    """
    (a1, a2), (r1, r2) = (float(a) for a in angles), (float(r) for r in rates)
    within1, within2 = abs(a1) <= limit_rad, abs(a2) <= limit_rad
    if within1 and within2:
        return (a1, a2), (r1, r2), False
    return ((min(limit_rad, max(-limit_rad, a1)), min(limit_rad, max(-limit_rad, a2))),
            (r1 if within1 else 0.0, r2 if within2 else 0.0), True)
