# SPDX-License-Identifier: Apache-2.0
"""`wirefish sweep --model-only`'s figures: no legend for what is not drawn, none over data."""

import matplotlib
from matplotlib.figure import Figure
import pytest
from wirefish_analysis.sweep import run_sweep, write_outputs

matplotlib.use('Agg')


@pytest.fixture
def saved_figures(monkeypatch):
    """Collect (legend labels, legend over its axes?) of every figure saved."""
    seen: list[tuple[list[str], bool]] = []
    save = Figure.savefig

    def record(fig, *args, **kwargs):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            legend = ax.get_legend()
            if legend is not None:
                over = legend.get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))
                seen.append(([t.get_text() for t in legend.get_texts()], over))
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, 'savefig', record)
    return seen


def test_a_model_only_sweep_promises_no_virtual_fish_and_covers_no_curve(saved_figures,
                                                                         tmp_path):
    grid, line = run_sweep(with_fish=False)
    write_outputs(grid, line, tmp_path)
    assert len(saved_figures) == 3
    labels = [label for labels, _ in saved_figures for label in labels]
    assert labels and not [label for label in labels if 'virtual fish' in label], labels
    assert not [labels for labels, over in saved_figures if over]
