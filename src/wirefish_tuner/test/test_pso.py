# SPDX-License-Identifier: Apache-2.0
"""PSO (eqs 26-27) on known test functions."""

import numpy as np
import pytest
from wirefish_tuner.pso import minimise, PsoOptions


def sphere(x):
    return np.sum((x - np.array([1.5, -2.0, 0.5])) ** 2, axis=-1)


def rosenbrock(x):
    return np.sum(100.0 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1 - x[:, :-1]) ** 2, axis=-1)


def rastrigin(x):
    return 10.0 * x.shape[1] + np.sum(x ** 2 - 10.0 * np.cos(2 * np.pi * x), axis=-1)


@pytest.mark.parametrize('loss, lower, upper, minimum', [
    (sphere, [-5.0] * 3, [5.0] * 3, [1.5, -2.0, 0.5]),
    (rosenbrock, [-2.0] * 2, [2.0] * 2, [1.0, 1.0]),
    (rastrigin, [-5.12] * 2, [5.12] * 2, [0.0, 0.0]),
])
def test_pso_finds_the_known_minimum(loss, lower, upper, minimum):
    options = PsoOptions(swarm_size=40, max_iterations=400, stall_iterations=400)
    result = minimise(loss, np.array(lower), np.array(upper), np.random.default_rng(1),
                      options)
    np.testing.assert_allclose(result.best_position, minimum, atol=1e-3)


def test_same_seed_gives_the_same_result():
    runs = [minimise(rastrigin, -np.ones(4) * 5, np.ones(4) * 5, np.random.default_rng(42))
            for _ in range(2)]
    np.testing.assert_array_equal(runs[0].position_history, runs[1].position_history)
    np.testing.assert_array_equal(runs[0].loss_history, runs[1].loss_history)


def test_different_seeds_explore_differently():
    runs = [minimise(rastrigin, -np.ones(4) * 5, np.ones(4) * 5, np.random.default_rng(s))
            for s in (1, 2)]
    assert not np.array_equal(runs[0].position_history, runs[1].position_history)


def test_flat_loss_stops_on_stall():
    options = PsoOptions(max_iterations=500, stall_iterations=7)
    result = minimise(lambda x: np.ones(len(x)), -np.ones(2), np.ones(2),
                      np.random.default_rng(0), options)
    assert result.stalled and result.iterations == 7


def test_run_stops_at_max_iterations_and_keeps_the_history():
    options = PsoOptions(max_iterations=25, stall_iterations=1000)
    result = minimise(sphere, -5 * np.ones(3), 5 * np.ones(3), np.random.default_rng(0),
                      options)
    assert result.iterations == 25
    assert result.loss_history.shape == (26,)
    assert result.position_history.shape == (26, 3)
    assert np.all(np.diff(result.loss_history) <= 0.0)


def test_particles_stay_inside_the_bounds():
    seen = []

    def loss(x):
        seen.append(x.copy())
        return -np.sum(x, axis=-1)  # drives every particle into the upper corner
    lower, upper = np.array([-1.0, 0.0]), np.array([2.0, 0.5])
    result = minimise(loss, lower, upper, np.random.default_rng(3), PsoOptions())
    everything = np.concatenate(seen)
    assert np.all(everything >= lower) and np.all(everything <= upper)
    np.testing.assert_allclose(result.best_position, upper)


def test_callback_sees_every_iteration():
    calls = []
    result = minimise(sphere, -5 * np.ones(3), 5 * np.ones(3), np.random.default_rng(0),
                      PsoOptions(max_iterations=10, stall_iterations=100),
                      callback=lambda i, loss, pos: calls.append((i, loss)))
    assert [i for i, _ in calls] == list(range(11))
    assert [loss for _, loss in calls] == list(result.loss_history)


@pytest.mark.parametrize('kwargs', [{'swarm_size': 0}, {'max_iterations': 0},
                                    {'inertia': float('nan')}, {'social': -1.0},
                                    {'stall_iterations': 0}])
def test_invalid_options_are_rejected(kwargs):
    with pytest.raises(ValueError):
        PsoOptions(**kwargs)


@pytest.mark.parametrize('lower, upper', [
    ([0.0, np.nan], [1.0, 1.0]), ([0.0, 0.0], [1.0, np.inf]), ([0.0, 2.0], [1.0, 1.0]),
])
def test_bounds_must_be_finite_and_ordered(lower, upper):
    with pytest.raises(ValueError):
        minimise(lambda x: np.sum(x ** 2, axis=1), lower, upper, np.random.default_rng(0))
