# SPDX-License-Identifier: Apache-2.0
"""The one fitting core of the retune service and action (wirefish_tuner.retune_core)."""

from dataclasses import replace
import math

import numpy as np
import pytest
from wirefish_cpg.gait_library import GaitLibrary
from wirefish_kinematics.geometry import FishGeometry
from wirefish_tuner.feasibility import FitLimits
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.retune_core import (FitCancelled, gait_of, retune, RetuneOrder,
                                        RetuneSettings)
from wirefish_tuner.wave_loss import WaveSpec

SHORT = RetuneSettings(pso=PsoOptions(swarm_size=20, max_iterations=30))


def order(**fields) -> RetuneOrder:
    values = {'c1': 0.15, 'c2': 1.0, 'k': 8.0, 'frequency_hz': 1.0}
    values.update(fields)
    return RetuneOrder(**values)


def test_the_section_5_2_wave_is_fitted_within_the_paper_rmse():
    outcome = retune(order(), RetuneSettings())
    assert outcome.success, outcome.message
    assert outcome.message.startswith('fitted: loss ')
    assert outcome.rmse_theta_deg[0] <= 1.7165 and outcome.rmse_theta_deg[1] <= 1.2817
    assert not outcome.from_library


@pytest.mark.parametrize('fields, words', [
    ({'c1': math.nan}, 'wave.c1 must be finite'),
    ({'frequency_hz': 12.0}, 'wave.frequency_hz must be in (0, 10] Hz'),
    ({'k': -1.0}, 'wave.k must be > 0'),
    ({'swarm_size': 1}, 'swarm_size must be 0 (default) or in [2, 2000]'),
    ({'max_iterations': 5001}, 'max_iterations must be 0 (default) or in [1, 5000]'),
    ({'c1': 1.0e6}, 'beyond any bend of the tail'),
    ({'k': 1.0e9}, 'k must be <= pi'),
    ({'c1': 1e308}, 'servo amplitudes'),
    ({'frequency_hz': 1e-300}, 'slowest beat'),
    ({'c2': -1e308}, 'servo amplitudes'),
])
def test_invalid_or_impossible_orders_are_rejected_before_fitting(fields, words):
    calls = []
    outcome = retune(order(**fields), SHORT, lambda *a: calls.append(a))
    assert not outcome.success
    assert outcome.message.startswith('rejected: ') and words in outcome.message
    assert calls == [] and outcome.params is None and outcome.iterations == 0


def test_a_fit_above_the_rmse_threshold_is_refused_with_its_figures():
    strict = RetuneSettings(pso=SHORT.pso, limits=FitLimits(max_rmse_deg=0.01))
    outcome = retune(order(), strict)
    assert not outcome.success
    assert outcome.message.startswith('fit refused, not applied: the fit misses the wave')
    assert f'{outcome.rmse_theta_deg[1]:.3f}' in outcome.message
    assert outcome.iterations > 0 and math.isfinite(outcome.loss)


def test_progress_reports_every_iteration_with_the_rmse_of_the_best_so_far():
    calls = []
    outcome = retune(order(), SHORT, lambda i, loss, rmse: calls.append((i, loss, *rmse)))
    assert [c[0] for c in calls] == list(range(outcome.iterations + 1))
    assert calls[-1][1] == outcome.loss
    np.testing.assert_allclose(calls[-1][2:], outcome.rmse_theta_deg)


def test_a_cancel_raised_by_progress_stops_the_fit_at_that_iteration():
    calls = []

    def progress(iteration, _loss, _rmse):
        calls.append(iteration)
        if iteration == 3:
            raise FitCancelled()
    with pytest.raises(FitCancelled):
        retune(order(), SHORT, progress)
    assert calls == [0, 1, 2, 3]


def test_the_same_seed_gives_the_same_fit():
    first, second = (retune(order(seed=7), SHORT) for _ in range(2))
    assert first.params == second.params and first.loss == second.loss


def test_a_wave_in_the_library_is_answered_from_it_without_fitting():
    fitted = retune(order(), SHORT)
    library = GaitLibrary().with_gait(gait_of(order(), fitted, SHORT))
    calls = []
    again = retune(order(seed=5), SHORT, lambda *a: calls.append(a), library)
    assert again.success and again.from_library and calls == []
    assert again.params == fitted.params and again.iterations == 0
    assert again.message.startswith('from the gait library')


def test_the_library_is_not_used_for_another_geometry_or_when_not_asked():
    fitted = retune(order(), SHORT)
    library = GaitLibrary().with_gait(gait_of(order(), fitted, SHORT))
    other_fish = RetuneSettings(pso=SHORT.pso, geometry=FishGeometry(l2=0.11))
    assert not retune(order(), other_fish, library=library).from_library
    assert not retune(order(use_library=False), SHORT, library=library).from_library


def test_infeasible_waves_are_refused_even_when_the_library_holds_them():
    fitted = retune(order(), SHORT)
    bogus = replace(gait_of(order(), fitted, SHORT), wave=WaveSpec(c1=1e6))
    outcome = retune(order(c1=1e6), SHORT, library=GaitLibrary().with_gait(bogus))
    assert not outcome.success and outcome.message.startswith('rejected')


def test_the_literal_mode_is_fitted_and_kept_apart_in_the_library():
    literal = retune(order(mode='literal'), SHORT)
    assert literal.success, literal.message
    phase_free = retune(order(), SHORT)
    assert literal.params != phase_free.params
    assert literal.params.frequency_hz == 1.0  # literal: v is the wave's frequency
    library = GaitLibrary().with_gait(gait_of(order(mode='literal'), literal, SHORT))
    assert retune(order(mode='literal'), SHORT, library=library).from_library
    assert not retune(order(), SHORT, library=library).from_library


def test_an_unknown_mode_is_rejected():
    outcome = retune(order(mode='exact'), SHORT)
    assert not outcome.success and 'mode must be empty or one of phase_free, literal' in \
        outcome.message
