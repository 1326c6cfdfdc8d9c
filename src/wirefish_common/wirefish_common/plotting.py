# SPDX-License-Identifier: Apache-2.0
"""
What every plot of the project shares: legends beside the data, and a moving mean.

No matplotlib import here (the callers have their figures): ``legend_beside`` places an axes'
legend to the right of it, outside, so that it never covers a curve; save such a figure with
``bbox_inches='tight'`` to keep the legend in the picture. ``moving_mean`` is the mean over a
time window centred on each sample, over what there is at the ends (no dip towards zero).
"""

from __future__ import annotations

from typing import Any

import numpy as np


def legend_beside(ax: Any, **options: Any) -> Any:
    """Draw ``ax``'s legend outside, to its right (``options`` go to ``ax.legend``)."""
    settings = {'loc': 'upper left', 'bbox_to_anchor': (1.01, 1.0), 'borderaxespad': 0.0,
                'fontsize': 8, **options}
    return ax.legend(**settings)


def moving_mean(t: np.ndarray, values: np.ndarray, window_s: float) -> np.ndarray:
    """Return the ``window_s`` moving mean of ``values`` sampled at ``t`` (median spacing)."""
    t, values = np.asarray(t, dtype=float), np.asarray(values, dtype=float)
    if len(t) < 3:
        return values
    step = float(np.median(np.diff(t)))
    width = min(len(t), max(1, int(round(window_s / step)) if step > 0.0 else 1))
    kernel = np.ones(width)
    return (np.convolve(values, kernel, mode='same')
            / np.convolve(np.ones(len(values)), kernel, mode='same'))
