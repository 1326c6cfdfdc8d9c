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
    (a1, a2), (r1, r2) = angles, rates
    if abs(a1) <= limit_rad and abs(a2) <= limit_rad:
        return (float(a1), float(a2)), (float(r1), float(r2)), False
    clipped = [(min(limit_rad, max(-limit_rad, a)), r if abs(a) <= limit_rad else 0.0)
               for a, r in ((a1, r1), (a2, r2))]
    return ((clipped[0][0], clipped[1][0]), (clipped[0][1], clipped[1][1]), True)
