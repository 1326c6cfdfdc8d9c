# SPDX-License-Identifier: Apache-2.0
"""Closed-form steady state of eq 1 against independent root finding and simulation."""

import numpy as np
import pytest
from scipy.optimize import brentq
from wirefish_cpg.oscillator import CpgParameters, NetworkArrays, PHASE, simulate
from wirefish_cpg.steady_state import (intrinsic_frequency_for, phase_difference_rate,
                                       stable_phase_difference, steady_state_phases,
                                       steady_state_servo_angles)

CASES = [
    CpgParameters(),  # Table 1
    CpgParameters(amplitude=(0.5, -0.6), w12=8.2, w21=-6.1, phi12=-1.4, phi21=1.9),
    CpgParameters(frequency_hz=2.0, amplitude=(1.0, 0.3), w12=-3.0, w21=-2.0, phi12=3.0,
                  phi21=-0.5),
    CpgParameters(amplitude=(0.2, 0.9), w12=0.0, w21=4.0, phi12=0.0, phi21=-2.0),
]


def independent_stable_root(p: CpgParameters) -> float:
    """Bracket the zeros of dDelta/dt on a fine grid and keep the one with negative slope."""
    r1, r2 = p.amplitude

    def rate(d):
        return phase_difference_rate(d, r1, r2, p.w12, p.w21, p.phi12, p.phi21)
    grid = np.linspace(-np.pi, np.pi, 721)
    values = rate(grid)
    roots = [brentq(rate, a, b) for a, b, fa, fb in
             zip(grid[:-1], grid[1:], values[:-1], values[1:]) if fa * fb < 0]
    stable = [x for x in roots if rate(x + 1e-6) < rate(x - 1e-6)]
    assert len(stable) == 1
    return stable[0]


def wrap(angle):
    return np.angle(np.exp(1j * angle))


@pytest.fixture(scope='module')
def settled():
    """Simulate every case as one batch: 40 s to settle, then one more second sampled."""
    net = NetworkArrays.stack(CASES)
    _, _, _, state = simulate(net, 40.0, 2e-3)
    t, angles, rates, later = simulate(net, 1.0, 2e-3, state=state)
    return state, t, angles, rates, later


@pytest.mark.parametrize('params', CASES)
def test_stable_phase_difference_is_the_stable_root_of_the_phase_equation(params):
    r1, r2 = params.amplitude
    closed = stable_phase_difference(r1, r2, params.w12, params.w21, params.phi12,
                                     params.phi21)
    assert wrap(closed - independent_stable_root(params)) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize('case', range(len(CASES)))
def test_simulated_network_settles_at_the_closed_form_phase_difference(case, settled):
    state = settled[0][case]
    delta, _ = steady_state_phases(CASES[case])
    assert wrap(state[PHASE, 1] - state[PHASE, 0] - delta) == pytest.approx(0.0, abs=1e-4)


@pytest.mark.parametrize('case', range(len(CASES)))
def test_simulated_network_turns_at_the_locked_frequency(case, settled):
    start, later = settled[0][case], settled[4][case]
    _, omega = steady_state_phases(CASES[case])
    assert later[PHASE, 0] - start[PHASE, 0] == pytest.approx(omega, rel=1e-6)


@pytest.mark.parametrize('case', range(len(CASES)))
def test_closed_form_outputs_match_the_settled_simulation(case, settled):
    state, t, angles, rates, _ = settled
    _, omega = steady_state_phases(CASES[case])
    shift = state[case, PHASE, 0] / omega  # closed form: oscillator 1's phase 0 at t = 0
    closed_angles, closed_rates = steady_state_servo_angles(CASES[case], t + shift)
    np.testing.assert_allclose(angles[:, case], closed_angles, atol=1e-4)
    np.testing.assert_allclose(rates[:, case], closed_rates, atol=1e-3)


@pytest.mark.parametrize('target_hz', [0.5, 1.0, 4.0])
def test_intrinsic_frequency_for_locks_the_network_to_the_target(target_hz):
    p = CASES[1]
    delta, _ = steady_state_phases(p)
    v = float(intrinsic_frequency_for(target_hz, p.amplitude[1], p.w12, p.phi12, delta))
    locked = CpgParameters(**{**p.__dict__, 'frequency_hz': v})
    assert steady_state_phases(locked)[1] == pytest.approx(2 * np.pi * target_hz, rel=1e-12)


def test_uncoupled_network_keeps_the_phase_difference_it_starts_with():
    assert stable_phase_difference(0.3, 0.4, 0.0, 0.0, 1.0, 2.0) == 0.0


def test_a_nan_coupling_gives_nan_not_a_plausible_phase():
    delta = stable_phase_difference(0.38, 0.47, np.nan, 0.64, 1.76, 1.06)
    assert np.isnan(delta)
