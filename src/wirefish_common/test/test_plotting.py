# SPDX-License-Identifier: Apache-2.0
"""Legends beside the data and the moving mean (pure; matplotlib without a display)."""

import matplotlib
import numpy as np
import pytest
from wirefish_common.plotting import legend_beside, moving_mean

matplotlib.use('Agg')


def test_the_legend_is_outside_the_axes():
    from matplotlib import pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label='a curve')
    legend = legend_beside(ax)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert legend.get_window_extent(renderer).x0 >= ax.get_window_extent(renderer).x1
    plt.close(fig)


def test_the_moving_mean_averages_what_there_is_at_the_ends():
    t = np.arange(0.0, 10.0, 0.1)
    mean = moving_mean(t, np.full_like(t, 0.2), 1.0)
    assert mean == pytest.approx(np.full_like(t, 0.2))  # no dip at either end


def test_the_moving_mean_removes_a_beat():
    t = np.arange(0.0, 10.0, 0.01)
    values = 0.2 + 0.05 * np.sin(2 * np.pi * 2.0 * t)  # a 2 Hz beat: two periods a window
    assert np.abs(moving_mean(t, values, 1.0)[100:-100] - 0.2).max() < 1e-3
