# SPDX-License-Identifier: Apache-2.0
"""The loss of eqs 24-25 on the closed-form steady state, and the section 5.2 fit."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from wirefish_cpg.cpg_node_parameters import CPG_PARAMETER_NAMES
from wirefish_cpg.from_rest import phases_from_rest
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import stable_phase_difference, steady_state_phases
from wirefish_kinematics.body_wave import body_positions
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.reference_loss import simulated_body_wave_loss
from wirefish_tuner.tuning import fit_gait
from wirefish_tuner.wave_loss import (body_wave_loss, desired_swing_angles, FREQUENCY_PENALTY,
                                      literal_body_wave_loss, literal_swing_rmse_deg,
                                      literal_waveforms, PAPER_LOWER, PAPER_UPPER,
                                      PARAMETER_NAMES, parameters_at, position_of,
                                      swarm_waveforms,
                                      swing_angle_rmse_deg, WaveFitProblem, waveform_loss,
                                      WaveSpec)

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


# --- the paper-literal mode: v = the wave's frequency, eq 1 from rest, [t_s, t_o] ---

def _eq1_from_rest_by_dop853(position, times, frequency_hz, alpha=20.0):
    """Integrate the six states of eq 1 from rest with scipy; return Theta (T, 2) at times."""
    w12, w21, phi12, phi21, big_r1, big_r2 = position

    def rhs(_, s):
        xi1, xi2, r1, r2, dr1, dr2 = s
        return [2 * np.pi * frequency_hz + r2 * w12 * np.sin(xi2 - xi1 - phi12),
                2 * np.pi * frequency_hz + r1 * w21 * np.sin(xi1 - xi2 - phi21),
                dr1, dr2, alpha * (alpha / 4 * (big_r1 - r1) - dr1),
                alpha * (alpha / 4 * (big_r2 - r2) - dr2)]

    sol = solve_ivp(rhs, (0.0, times[-1]), [0.0] * 6, method='DOP853', rtol=1e-11, atol=1e-12,
                    t_eval=times)
    return np.stack([sol.y[2] * np.cos(sol.y[0]), sol.y[3] * np.cos(sol.y[1])], axis=-1)


@pytest.mark.parametrize('position', POSITIONS, ids=range(len(POSITIONS)))
def test_literal_loss_equals_an_independent_time_domain_integration(position):
    times = PROBLEM.window_times()
    angles = _eq1_from_rest_by_dop853(position, times, PROBLEM.wave.frequency_hz)
    g = PROBLEM.geometry
    beta1 = g.rd1 * angles[:, 0] / g.r1
    beta2 = g.rd2 * angles[:, 1] / g.r2 - beta1
    stations = np.array([g.l1, g.l1 + g.l2])
    _, y = body_positions(stations, beta1, beta2, g)
    envelope = 0.15 * stations + stations ** 2
    y_body = envelope * np.sin(8.0 * stations - 2 * np.pi * times[:, None])
    independent = np.trapezoid(np.abs(y_body - y).sum(axis=1), times)
    literal = literal_body_wave_loss(position[None], PROBLEM)[0]
    assert literal == pytest.approx(independent, rel=1e-7)


def test_literal_waveforms_are_eq1_from_rest_at_the_wave_frequency():
    times = PROBLEM.window_times()
    angles = literal_waveforms(POSITIONS[1][None], PROBLEM)[0]
    np.testing.assert_allclose(angles, _eq1_from_rest_by_dop853(POSITIONS[1], times, 1.0),
                               atol=1e-8)


def test_literal_swarm_loss_equals_the_particle_by_particle_loss():
    swarm = np.random.default_rng(6).uniform(PAPER_LOWER, PAPER_UPPER, (25, 6))
    together = literal_body_wave_loss(swarm, PROBLEM)
    apart = [literal_body_wave_loss(x[None], PROBLEM)[0] for x in swarm]
    np.testing.assert_allclose(together, apart, rtol=1e-12)


def test_literal_window_defaults_start_after_table1_has_locked():
    xi1, xi2 = phases_from_rest(PROBLEM.window_start_s, 1.0, 0.38, 0.47, -0.41, 0.64, 1.76,
                                1.06)
    assert abs(xi2 - xi1 - stable_phase_difference(0.38, 0.47, -0.41, 0.64, 1.76, 1.06)) < 1e-3


def test_literal_fit_reaches_the_paper_swing_angle_rmse():
    result = fit_gait(PROBLEM, np.random.default_rng(0), PsoOptions(max_iterations=300),
                      mode='literal')
    assert result.params.frequency_hz == PROBLEM.wave.frequency_hz
    assert np.all(result.rmse_theta_deg <= PAPER_RMSE_DEG)
    assert result.loss == pytest.approx(
        literal_body_wave_loss(result.pso.best_position[None], PROBLEM)[0], rel=1e-12)


def test_table1_scores_worse_literally_than_phase_free():
    literal = literal_swing_rmse_deg(TABLE1[None], PROBLEM)[0]
    assert np.all(literal > swing_angle_rmse_deg(TABLE1[None], PROBLEM)[0])


def test_chord_theta_bar_is_the_arcsine_of_the_wave_over_q():
    chord = desired_swing_angles(PROBLEM, 'chord')
    y = PROBLEM.desired()
    np.testing.assert_allclose(np.sin(chord) * PROBLEM.stations(), y, atol=1e-15)
    assert np.all(np.abs(chord) >= np.abs(desired_swing_angles(PROBLEM, 'axial')))


def test_unknown_fit_mode_is_refused():
    with pytest.raises(ValueError, match='mode'):
        fit_gait(PROBLEM, np.random.default_rng(0), mode='paper')


@pytest.mark.parametrize('window', [(5.0, 5.0), (-1.0, 4.0), (10.0, 2.0), (0.0, float('nan'))])
def test_invalid_literal_windows_are_refused(window):
    with pytest.raises(ValueError, match='window'):
        WaveFitProblem(window_start_s=window[0], window_end_s=window[1])


def test_the_tuned_position_names_are_cpg_parameter_names():
    assert set(PARAMETER_NAMES) <= set(CPG_PARAMETER_NAMES)
