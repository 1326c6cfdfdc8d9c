# SPDX-License-Identifier: Apache-2.0
"""tuner_node as a separate process: fits, refusals, bursts, the library, applying to cpg_node."""

import math

from cpg_probe import CPG_NODE, LATCHED, max_step_ratio, WAIT_S
import numpy as np
import pytest
from ros_utils import spin_until
from wirefish_common.qos import reliable
from wirefish_cpg.gait_library import load_library
from wirefish_msgs.msg import BodyWaveSpec
from wirefish_msgs.srv import RetuneGait

# It mostly waits (0.28 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]
PAPER_RMSE_DEG = (1.7165, 1.2817)
CPG_NAMES = ['frequency_hz', 'amplitude_1', 'amplitude_2', 'offset_1', 'offset_2', 'w12',
             'w21', 'phi12', 'phi21', 'alpha']


def retune_request(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0, apply=False, seed=0,
                   max_iterations=0, swarm_size=0) -> RetuneGait.Request:
    request = RetuneGait.Request(apply=apply, seed=seed, max_iterations=max_iterations,
                                 swarm_size=swarm_size)
    request.wave = BodyWaveSpec(c1=c1, c2=c2, k=k, frequency_hz=frequency_hz)
    return request


def test_retune_returns_success_with_the_fitted_parameters(spawn, tuner, probe):
    tuner()
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    response = probe.call(client, retune_request())
    assert response.success, response.message
    assert response.iterations >= 1 and response.elapsed_s > 0.0
    assert 0.0 < response.loss < 0.01
    assert response.rmse_theta_deg[0] <= PAPER_RMSE_DEG[0]
    assert response.rmse_theta_deg[1] <= PAPER_RMSE_DEG[1]
    assert 0.0 < response.params.frequency_hz <= 10.0
    assert response.params.alpha == 20.0


BAD_REQUESTS = [
    ({'frequency_hz': 0.0}, 'frequency_hz'),
    ({'frequency_hz': 12.0}, 'frequency_hz'),
    ({'frequency_hz': math.nan}, 'frequency_hz'),
    ({'k': 0.0}, 'k'),
    ({'k': -3.0}, 'k'),
    ({'c1': math.inf}, 'c1'),
    ({'c2': math.nan}, 'c2'),
    ({'swarm_size': 1}, 'swarm_size'),
    ({'max_iterations': 100000}, 'max_iterations'),
]


def test_bad_requests_are_refused_with_reasons_and_leave_the_cpg_untouched(spawn, tuner, probe):
    spawn([CPG_NODE])
    tuner()
    probe.wait_samples(20)
    # The latched cpg_params may arrive after the first samples on a loaded machine: count
    # the announcements only once it is in.
    assert spin_until(probe.executor, lambda: len(probe.cpg_params) > 0, WAIT_S)
    before = probe.get_parameters(CPG_NAMES)
    announced = len(probe.cpg_params)
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    for fields, culprit in BAD_REQUESTS:
        response = probe.call(client, retune_request(apply=True, **fields))
        assert not response.success, fields
        assert culprit in response.message, (fields, response.message)
    assert probe.get_parameters(CPG_NAMES) == before
    assert len(probe.cpg_params) == announced


IMPOSSIBLE_WAVES = [
    ({'c1': 1.0e6}, 'swing angles up to 90/90 deg, beyond any bend of the tail'),
    ({'k': 1.0e9}, 'k must be <= pi / 0.1 = 31.42 rad/m'),
    ({'c1': 1e308}, 'servo amplitudes'),
    ({'frequency_hz': 1e-300}, 'below the slowest beat'),
    ({'c2': -1e308}, 'servo amplitudes'),
]


def test_impossible_waves_are_refused_before_fitting_and_change_nothing(spawn, tuner, probe):
    spawn([CPG_NODE])
    tuner()
    probe.wait_samples(20)
    assert spin_until(probe.executor, lambda: len(probe.cpg_params) > 0, WAIT_S)
    before = probe.get_parameters(CPG_NAMES)
    announced = len(probe.cpg_params)
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    for fields, reason in IMPOSSIBLE_WAVES:
        response = probe.call(client, retune_request(apply=True, **fields))
        assert not response.success, fields
        assert response.message.startswith('rejected: '), response.message
        assert reason in response.message, (fields, response.message)
        assert response.iterations == 0  # refused before fitting
    assert probe.get_parameters(CPG_NAMES) == before
    assert len(probe.cpg_params) == announced
    waves = []
    probe.node.create_subscription(BodyWaveSpec, 'target_wave', waves.append, LATCHED)
    assert spin_until(probe.executor,
                      lambda: probe.node.count_publishers('target_wave') > 0, WAIT_S)
    spin_until(probe.executor, lambda: waves, 2.0)
    assert waves == []  # nothing latched: no fit succeeded


def test_a_fit_worse_than_max_rmse_is_answered_with_its_figures_and_not_applied(
        spawn, tuner, probe):
    spawn([CPG_NODE])
    tuner('-p', 'max_rmse_deg:=0.01')
    probe.wait_samples(20)
    assert spin_until(probe.executor, lambda: len(probe.cpg_params) > 0, WAIT_S)
    before = probe.get_parameters(CPG_NAMES)
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    response = probe.call(client, retune_request(apply=True, max_iterations=10))
    assert not response.success
    assert response.message.startswith('fit refused, not applied: the fit misses the wave')
    assert response.iterations == 10 and 0.0 < response.loss < 1.0
    assert f'{response.rmse_theta_deg[0]:.3f}/{response.rmse_theta_deg[1]:.3f}' in \
        response.message
    assert probe.get_parameters(CPG_NAMES) == before


def test_apply_sets_the_cpg_parameters_and_the_output_converges_without_a_step(
        spawn, tuner, probe):
    spawn([CPG_NODE])
    tuner()
    probe.wait_samples(200)
    start = len(probe.servo)
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    response = probe.call(client, retune_request(c1=0.10, c2=0.8, k=6.0, frequency_hz=1.5,
                                                 apply=True, seed=3))
    assert response.success, response.message
    applied = probe.get_parameters(CPG_NAMES)
    fitted = response.params
    assert applied['frequency_hz'] == fitted.frequency_hz
    assert (applied['amplitude_1'], applied['amplitude_2']) == tuple(fitted.amplitude)
    assert (applied['w12'], applied['w21'], applied['phi12'], applied['phi21']) == (
        fitted.w12, fitted.w21, fitted.phi12, fitted.phi21)
    probe.wait_samples(500)
    t, positions, velocities = probe.trace(start)
    assert max_step_ratio(t, positions, velocities) <= 1.0
    last_period = positions[t > t[-1] - 1.0 / 1.5]
    np.testing.assert_allclose(np.abs(last_period).max(axis=0), np.abs(fitted.amplitude),
                               rtol=0.03)
    assert spin_until(probe.executor,
                      lambda: probe.cpg_params[-1].frequency_hz == fitted.frequency_hz, WAIT_S)
    waves = []
    probe.node.create_subscription(BodyWaveSpec, 'target_wave', waves.append, LATCHED)
    assert spin_until(probe.executor, lambda: waves, WAIT_S)  # latched once applied
    assert (waves[-1].c1, waves[-1].c2, waves[-1].k, waves[-1].frequency_hz) == (
        0.10, 0.8, 6.0, 1.5)


def test_a_fit_not_applied_is_stored_in_the_library_and_latches_no_target_wave(
        spawn, tuner, probe, library_path):
    tuner()
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    response = probe.call(client, retune_request(c2=0.9, max_iterations=30, swarm_size=20))
    assert response.success, response.message
    stored = load_library(library_path).gaits
    assert [(g.wave.c1, g.wave.c2, g.wave.k, g.wave.frequency_hz) for g in stored] == [
        (0.15, 0.9, 8.0, 1.0)]
    assert stored[0].loss == response.loss and stored[0].params.w12 == response.params.w12
    waves = []
    probe.node.create_subscription(BodyWaveSpec, 'target_wave', waves.append, LATCHED)
    spin_until(probe.executor, lambda: waves, 2.0)
    assert waves == []  # the CPG does not run this wave


def test_a_second_request_while_one_runs_is_refused_as_busy(spawn, tuner, probe):
    tuner('-p', 'stall_iterations:=5000')
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    assert spin_until(probe.executor, client.service_is_ready, WAIT_S)
    long_run = client.call_async(retune_request(max_iterations=5000, swarm_size=2000))
    spin_until(probe.executor, long_run.done, 1.0)  # let the long fit start first
    assert not long_run.done()
    response = probe.call(client, retune_request())
    assert not response.success
    assert 'busy' in response.message
    assert not long_run.done()


# One client's own queue keeps 10 requests (rclpy's default service QoS): more at once are
# lost inside that client before they are sent, which no server can answer.
@pytest.mark.parametrize('clients, requests_each', [(50, 1), (1, 10)])
def test_a_burst_of_requests_is_answered_every_one(spawn, tuner, probe, clients, requests_each):
    tuner()
    # Every client's response reader receives every answer of the service (one DDS topic) and
    # keeps its depth of them until its own executor takes them: a client at rclpy's default
    # depth of 10 that takes nothing for 10 paced answers (200 ms) loses its own, whatever the
    # server did (this probe, its 50 clients on one thread, held for 0.3 s: 45 of 50 answered;
    # 1 s: 11). The probe's clients keep the whole burst, so what is counted is the server's
    # answers; the pacing that protects default clients is test_answered_service's.
    burst = reliable(clients * requests_each)
    made = [probe.node.create_client(RetuneGait, 'retune_gait', qos_profile=burst)
            for _ in range(clients)]
    assert spin_until(probe.executor, lambda: all(c.service_is_ready() for c in made), WAIT_S)
    futures = [c.call_async(retune_request(seed=i)) for c in made for i in range(requests_each)]
    # Bounded: one default fit (~0.1 s alone) and the refusals paced 20 ms apart (~1 s), on a
    # loaded machine.
    spin_until(probe.executor, lambda: all(f.done() for f in futures), 60.0)
    answered = [f.result() for f in futures if f.done()]
    assert len(answered) == clients * requests_each
    assert sum(r.success for r in answered) >= 1
    assert all(r.success or 'busy' in r.message for r in answered)


def test_apply_without_a_cpg_node_fails_with_a_reason(spawn, tuner, probe):
    tuner('-p', 'apply_timeout_s:=1.0')
    client = probe.node.create_client(RetuneGait, 'retune_gait')
    response = probe.call(client, retune_request(apply=True, max_iterations=5))
    assert not response.success
    assert 'cpg_node/set_parameters_atomically' in response.message
    assert response.iterations == 5  # the fit itself is still reported
