"""The servo limit applied to the CPG's output before it becomes a command."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike


def clamp_to_limit(angles: ArrayLike, rates: ArrayLike, limit_rad: float
                   ) -> tuple[np.ndarray, np.ndarray, bool]:
    """
    Return (angles clipped to [-limit, limit] rad, rates, whether any angle was clipped).

    A clipped servo holds still at the limit, so its rate is 0 (rad/s): a consumer integrating
    the rate must not run past the angle.
    """
    angles = np.asarray(angles, dtype=float)
    rates = np.asarray(rates, dtype=float)
    clipped = np.abs(angles) > limit_rad
    if not clipped.any():
        return angles, rates, False
    return angles.clip(-limit_rad, limit_rad), np.where(clipped, 0.0, rates), True
