# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the bridge package's tests."""

import numpy as np
import pytest
from wirefish_analysis.fig11 import speed_sweep, SteadyRun


@pytest.fixture(scope='session')
def fig11_runs() -> list[SteadyRun]:
    """Return the virtual fish's steady runs at 5 cm over the paper's 1-8 Hz (default servo)."""
    runs = speed_sweep(np.arange(1.0, 8.01, 0.5))
    print('f, speed, amplitude:', [(r.frequency_hz, round(r.speed, 3),
                                    round(r.tail_tip_amplitude, 4)) for r in runs])
    return runs
