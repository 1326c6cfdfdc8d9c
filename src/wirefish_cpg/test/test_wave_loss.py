"""The loss of eqs 24-25 on the closed-form steady state, and the section 5.2 fit."""

import numpy as np
import pytest
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.pso import PsoOptions
from wirefish_cpg.reference_loss import simulated_body_wave_loss
from wirefish_cpg.steady_state import steady_state_phases
from wirefish_cpg.tuning import fit_gait
from wirefish_cpg.wave_loss import (body_wave_loss, FREQUENCY_PENALTY, PAPER_LOWER,
                                    PAPER_UPPER, parameters_at, position_of, swarm_waveforms,
                                    WaveFitProblem, waveform_loss, WaveSpec)

PAPER_RMSE_DEG = (1.7165, 1.2817)
TABLE1 = position_of(CpgParameters())
PROBLEM = WaveFitProblem()  # section 5.2: c1 = 0.15, c2 = 1, k = 8, 1 Hz; default geometry


@pytest.fixture(scope='module')
def fit():
    return fit_gait(PROBLEM, np.random.default_rng(0))


def test_table1_fits_the_tailward_wave_far_better_than_the_headward_one():
    tailward = body_wave_loss(TABLE1[None], PROBLEM)[0]
    headward = body_wave_loss(TABLE1[None], WaveFitProblem(reverse_wave=True))[0]
    assert tailward < 0.5 * headward


POSITIONS = [
    TABLE1,
    np.array([8.25, -6.14, -1.38, 1.85, 0.52, -0.60]),
    np.array([-3.0, 4.0, 2.0, -1.0, -0.3, 1.1]),
    np.array([5.0, 5.0, 0.5, 0.5, 1.2, 0.4]),
]


@pytest.mark.parametrize('position', POSITIONS, ids=range(len(POSITIONS)))
def test_closed_form_loss_equals_the_loss_of_the_integrated_network(position):
    exact = body_wave_loss(position[None], PROBLEM)[0]
    simulated = simulated_body_wave_loss(position, PROBLEM, settle_s=40.0)
    assert simulated == pytest.approx(exact, rel=1e-4)


def test_loss_is_proportional_to_the_number_of_periods_in_the_window():
    one = body_wave_loss(TABLE1[None], PROBLEM)[0]
    three = body_wave_loss(TABLE1[None], WaveFitProblem(window_periods=3))[0]
    assert three == pytest.approx(3.0 * one, rel=1e-12)


def test_swarm_loss_equals_the_particle_by_particle_loss():
    swarm = np.random.default_rng(5).uniform(PAPER_LOWER, PAPER_UPPER, (25, 6))
    together = body_wave_loss(swarm, PROBLEM)
    apart = [body_wave_loss(x[None], PROBLEM)[0] for x in swarm]
    np.testing.assert_allclose(together, apart, rtol=1e-12)


def test_referencing_oscillator1_is_as_good_as_the_best_time_shift(fit):
    fine = WaveFitProblem(samples_per_period=720)
    angles = swarm_waveforms(fit.pso.best_position[None], fine).angles[0]
    shifted = np.stack([np.roll(angles, s, axis=0) for s in range(720)])
    best_shift = waveform_loss(shifted, fine).min()
    assert body_wave_loss(fit.pso.best_position[None], fine)[0] <= 1.01 * best_shift


def test_section_5_2_fit_reaches_the_paper_swing_angle_rmse(fit):
    assert fit.rmse_theta_deg[0] <= PAPER_RMSE_DEG[0]
    assert fit.rmse_theta_deg[1] <= PAPER_RMSE_DEG[1]


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_section_5_2_fit_beats_table1_for_other_seeds(seed):
    result = fit_gait(PROBLEM, np.random.default_rng(seed))
    assert result.loss < body_wave_loss(TABLE1[None], PROBLEM)[0]
    assert np.all(result.rmse_theta_deg <= PAPER_RMSE_DEG)


def test_same_seed_gives_the_same_fit(fit):
    again = fit_gait(PROBLEM, np.random.default_rng(0))
    assert again.params == fit.params and again.loss == fit.loss


def test_fitted_parameters_lock_to_the_wave_frequency(fit):
    _, omega = steady_state_phases(fit.params)
    assert omega == pytest.approx(2.0 * np.pi * PROBLEM.wave.frequency_hz, rel=1e-12)


def test_particles_that_cannot_lock_with_a_positive_frequency_are_penalised():
    # Strong coupling can shift the locked frequency by more than the wave's 1 Hz, so some
    # particles would need v <= 0 (about 1 % of the box).
    swarm = np.random.default_rng(0).uniform(PAPER_LOWER, PAPER_UPPER, (5000, 6))
    intrinsic = swarm_waveforms(swarm, PROBLEM).intrinsic_hz
    assert np.any(intrinsic <= 0.0)
    losses = body_wave_loss(swarm, PROBLEM)
    assert np.all(losses[intrinsic <= 0.0] >= FREQUENCY_PENALTY)
    assert np.all(losses[intrinsic > 0.0] < FREQUENCY_PENALTY)


def test_parameters_at_keeps_the_tuned_values_and_the_default_alpha(fit):
    params = parameters_at(fit.pso.best_position, PROBLEM)
    np.testing.assert_allclose(position_of(params), fit.pso.best_position)
    assert params.alpha == 20.0 and params.offset == (0.0, 0.0)


def test_few_iterations_already_give_a_usable_fit():
    result = fit_gait(PROBLEM, np.random.default_rng(0), PsoOptions(max_iterations=10))
    assert result.iterations == 10
    assert result.loss < 0.5 * body_wave_loss(TABLE1[None], PROBLEM)[0]


@pytest.mark.parametrize('kwargs', [{'k': 0.0}, {'frequency_hz': 0.0}, {'frequency_hz': 11.0},
                                    {'c1': float('nan')}, {'c2': float('inf')}])
def test_invalid_waves_are_rejected(kwargs):
    with pytest.raises(ValueError):
        WaveSpec(**kwargs)
