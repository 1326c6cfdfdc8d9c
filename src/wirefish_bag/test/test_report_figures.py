# SPDX-License-Identifier: Apache-2.0
"""The report's figures: legends beside the curves, one axis per angle, the speed's mean."""

from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest
from wirefish_bag.report import attitude_figure, body_wave_figure, cpg_figure, speed_figure

matplotlib.use('Agg')
T = np.arange(0.0, 10.0, 0.01)


def legends_over_data(fig) -> list[str]:
    """Return the labels of every legend that lies over its axes (it may cover a curve)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    over = []
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None and legend.get_window_extent(renderer).overlaps(
                ax.get_window_extent(renderer)):
            over.append(', '.join(text.get_text() for text in legend.get_texts()))
    return over


FIGURES = {
    'cpg_outputs': lambda: cpg_figure(T, np.column_stack([np.sin(T), np.cos(T)])),
    'body_wave': lambda: body_wave_figure(SimpleNamespace(
        x=np.linspace(0, 0.3, 20), y=np.zeros(20), y_desired=np.zeros(20))),
    'speed': lambda: speed_figure([(1.0, 0.2), (2.0, 0.21)], list(zip(T, 0.2 + 0 * T))),
    'attitude': lambda: attitude_figure(T, np.zeros((len(T), 3))),
}


@pytest.mark.parametrize('make', FIGURES.values(), ids=FIGURES.keys())
def test_no_legend_covers_the_data(make):
    fig = make()
    assert not legends_over_data(fig)
    matplotlib.pyplot.close(fig)


def test_each_angle_has_its_axis_and_yaw_is_unwrapped():
    yaw = np.radians(170.0) + 0.2 * T  # turning left through +180 deg
    fig = attitude_figure(T, np.column_stack([0.01 * np.sin(T), 0.02 * np.cos(T), yaw]))
    roll, pitch, yaw_axis = fig.axes
    drawn_yaw = yaw_axis.get_lines()[0].get_ydata()
    assert np.max(np.abs(np.diff(drawn_yaw))) < 1.0  # no jump of 360 deg at +-180
    assert drawn_yaw[-1] == pytest.approx(np.degrees(yaw[-1]))
    assert np.ptp(roll.get_lines()[0].get_ydata()) > 1.0  # roll fills its own axis
    matplotlib.pyplot.close(fig)


def test_the_speed_shows_the_ground_truths_mean_beside_its_beat():
    beat = 0.2 + 0.05 * np.sin(2 * np.pi * 3.0 * T)
    fig = speed_figure([(5.0, 0.2)], list(zip(T, beat)))
    lines = {line.get_label(): line.get_ydata() for line in fig.axes[0].get_lines()}
    mean = lines['virtual fish, 1 s mean']
    assert np.abs(mean[150:-150] - 0.2).max() < 1e-3 and np.ptp(lines[
        'virtual fish, raw (ground truth)']) > 0.09
    matplotlib.pyplot.close(fig)


def test_a_legend_over_the_axes_is_found():
    from matplotlib import pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], label='a curve')
    ax.legend(loc='center')
    assert legends_over_data(fig) == ['a curve']
    plt.close(fig)
