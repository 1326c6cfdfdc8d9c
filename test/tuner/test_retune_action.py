# SPDX-License-Identifier: Apache-2.0
"""The retune_gait action across processes: feedback, result, cancel, rejection, library."""

import os
import signal
import time

from action_msgs.msg import GoalStatus
from cpg_probe import CPG_NODE, LATCHED, max_step_ratio, WAIT_S
import numpy as np
import pytest
from rclpy.action import ActionClient
from ros_utils import spin_until
from rosgraph_msgs.msg import Clock
from wirefish_common.qos import latched, reliable
from wirefish_cpg.gait_library import Gait, GaitLibrary, load_library, save_library
from wirefish_msgs.action import RetuneGait as RetuneGaitAction
from wirefish_msgs.msg import BodyWaveSpec
from wirefish_msgs.srv import RetuneGait
from wirefish_operator.goal_sender import FEEDBACK_DEPTH, GoalSender

# It mostly waits (0.20 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]
CPG_NAMES = ['frequency_hz', 'amplitude_1', 'amplitude_2', 'w12', 'w21', 'phi12', 'phi21',
             'alpha']


def goal(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0, **fields) -> RetuneGaitAction.Goal:
    message = RetuneGaitAction.Goal(**fields)
    message.wave = BodyWaveSpec(c1=c1, c2=c2, k=k, frequency_hz=frequency_hz)
    return message


class GoalRun:
    """One goal sent from the probe: its handle, feedback and result."""

    def __init__(self, probe, client: ActionClient, message: RetuneGaitAction.Goal) -> None:
        self.probe, self.feedback = probe, []
        assert spin_until(probe.executor, client.server_is_ready, WAIT_S), 'no action server'
        # As `wirefish retune` sends it: a goal whose answer is lost is adopted (goal_sender).
        # The sender stays: it delivers the goal's feedback (also after the result).
        self.sender = GoalSender(probe.node, client,
                                 lambda s: probe.executor.spin_once(timeout_sec=s),
                                 'retune_gait', RetuneGaitAction)
        self.handle = self.sender.send(message, lambda f: self.feedback.append(f.feedback),
                                       time.monotonic() + WAIT_S)
        assert self.handle is not None, 'goal never answered'
        self._result = None

    def result(self, timeout_s: float = 120.0):
        """Wait for and return the result response (status, result)."""
        if self._result is None:
            future = self.handle.get_result_async()
            assert spin_until(self.probe.executor, future.done, timeout_s), 'no result'
            self._result = future.result()
        return self._result


def action_client(probe) -> ActionClient:
    # Every iteration's feedback kept (rclpy's default keeps 10 of a fast fit's hundreds).
    return ActionClient(probe.node, RetuneGaitAction, 'retune_gait',
                        feedback_sub_qos_profile=reliable(1000))


@pytest.fixture
def action(probe) -> ActionClient:
    return action_client(probe)


def test_feedback_every_iteration_and_the_result_equal_the_service_for_the_same_seed(
        tuner, probe, action):
    tuner()
    run = GoalRun(probe, action, goal(seed=4, max_iterations=25, swarm_size=20,
                                      use_library=False))
    assert run.handle.accepted
    answer = run.result()
    assert answer.status == GoalStatus.STATUS_SUCCEEDED, answer.result.message
    result = answer.result
    # Feedback can trail the result by a few ms: wait for the last iteration's.
    spin_until(probe.executor, lambda: len(run.feedback) == result.iterations + 1, WAIT_S)
    assert [f.iteration for f in run.feedback] == list(range(result.iterations + 1))
    assert all(f.max_iterations == 25 for f in run.feedback)
    losses = [f.best_loss for f in run.feedback]
    assert np.all(np.diff(losses) <= 0.0) and losses[-1] == result.loss
    np.testing.assert_array_equal(run.feedback[-1].rmse_theta_deg, result.rmse_theta_deg)
    service = probe.node.create_client(RetuneGait, 'retune_gait')
    request = RetuneGait.Request(seed=4, max_iterations=25, swarm_size=20)
    request.wave = goal().wave
    response = probe.call(service, request)
    assert response.success and not result.applied and not result.from_library
    assert (response.params, response.loss, response.iterations) == (
        result.params, result.loss, result.iterations)
    np.testing.assert_array_equal(response.rmse_theta_deg, result.rmse_theta_deg)


def test_a_feedback_reader_that_joins_after_the_fit_still_gets_every_iteration(
        tuner, probe, action):
    # GoalSender's reader is made just before its goal: the tuner's writer may match it only
    # after a short fit has published its feedback. Here it joins after the result, for sure.
    tuner()
    run = GoalRun(probe, action, goal(seed=5, max_iterations=5, swarm_size=20,
                                      use_library=False))
    answer = run.result()
    assert answer.status == GoalStatus.STATUS_SUCCEEDED, answer.result.message
    goal_id = bytes(run.handle.goal_id.uuid)
    heard = []
    probe.node.create_subscription(
        RetuneGaitAction.Impl.FeedbackMessage, 'retune_gait/_action/feedback',
        lambda m: heard.append(m.feedback.iteration) if bytes(m.goal_id.uuid) == goal_id
        else None, latched(FEEDBACK_DEPTH))
    iterations = list(range(answer.result.iterations + 1))
    spin_until(probe.executor, lambda: heard == iterations, WAIT_S)
    assert heard == iterations


def test_cancel_stops_the_fit_within_one_iteration_and_leaves_the_cpg_untouched(
        spawn, tuner, probe, action):
    spawn([CPG_NODE])
    tuner('-p', 'stall_iterations:=5000')
    probe.wait_samples(20)
    assert spin_until(probe.executor, lambda: probe.cpg_params, WAIT_S)
    before, announced = probe.get_parameters(CPG_NAMES), len(probe.cpg_params)
    run = GoalRun(probe, action, goal(c2=0.9, apply=True, max_iterations=5000,
                                      swarm_size=2000))
    assert spin_until(probe.executor, lambda: len(run.feedback) >= 2, WAIT_S)
    canceling = run.handle.cancel_goal_async()
    assert spin_until(probe.executor, canceling.done, WAIT_S)
    seen_at_cancel = run.feedback[-1].iteration
    answer = run.result()
    assert answer.status == GoalStatus.STATUS_CANCELED
    assert answer.result.message.startswith('canceled')
    assert not answer.result.applied
    # The fit checks for the cancel before each iteration's feedback: at most the iteration
    # running when the cancel was accepted finishes.
    assert run.feedback[-1].iteration <= seen_at_cancel + 1
    assert probe.get_parameters(CPG_NAMES) == before
    assert len(probe.cpg_params) == announced


def test_a_goal_sent_during_a_fit_is_rejected_and_the_service_answers_busy(
        tuner, probe, action):
    tuner('-p', 'stall_iterations:=5000')
    first = GoalRun(probe, action, goal(max_iterations=5000, swarm_size=2000))
    assert spin_until(probe.executor, lambda: first.feedback, WAIT_S)  # the fit is running
    second = GoalRun(probe, action, goal(frequency_hz=1.5))
    assert not second.handle.accepted  # the documented answer: rejected at once
    service = probe.node.create_client(RetuneGait, 'retune_gait')
    request = RetuneGait.Request()
    request.wave = goal().wave
    assert 'busy' in probe.call(service, request).message
    first.handle.cancel_goal_async()
    assert first.result().status == GoalStatus.STATUS_CANCELED
    third = GoalRun(probe, action, goal(max_iterations=3))
    assert third.handle.accepted  # free again once the first ended


@pytest.mark.parametrize('fields, words', [
    ({'c1': 1.0e6}, 'beyond any bend of the tail'),
    ({'frequency_hz': 12.0}, 'wave.frequency_hz must be in (0, 10] Hz'),
    ({'swarm_size': 1}, 'swarm_size'),
])
def test_the_service_rules_refuse_goals_too(tuner, probe, action, fields, words):
    tuner()
    answer = GoalRun(probe, action, goal(apply=True, **fields)).result()
    assert answer.status == GoalStatus.STATUS_ABORTED
    assert answer.result.message.startswith('rejected: ') and words in answer.result.message
    assert not answer.result.applied and answer.result.iterations == 0


def test_the_same_wave_twice_comes_from_the_library_and_survives_a_restart(
        tuner, probe, action, library_path):
    process = tuner()
    first = GoalRun(probe, action, goal(c1=0.12, frequency_hz=1.2)).result().result
    assert first.success and not first.from_library and first.iterations > 0
    second = GoalRun(probe, action, goal(c1=0.12, frequency_hz=1.2, seed=9)).result().result
    assert second.success and second.from_library and second.iterations == 0
    assert (second.params.w12, second.loss) == (first.params.w12, first.loss)
    assert second.message.startswith('from the gait library')
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=WAIT_S) == 0
    tuner()
    action_after = action_client(probe)
    third = GoalRun(probe, action_after, goal(c1=0.12, frequency_hz=1.2)).result().result
    assert third.from_library and third.loss == first.loss
    assert len(load_library(library_path).gaits) == 1


def test_another_geometry_never_reuses_a_gait(tuner, probe, action):
    process = tuner()
    assert GoalRun(probe, action, goal()).result().result.success
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=WAIT_S) == 0
    tuner('-p', 'l2:=0.11')
    again = action_client(probe)
    result = GoalRun(probe, again, goal()).result().result
    assert result.success and not result.from_library and result.iterations > 0


def test_applying_a_gait_from_the_library_makes_no_servo_step(spawn, tuner, probe, action):
    spawn([CPG_NODE])
    tuner()
    wave = {'c1': 0.10, 'c2': 0.8, 'k': 6.0, 'frequency_hz': 1.5}
    assert GoalRun(probe, action, goal(**wave)).result().result.success  # now in the library
    probe.wait_samples(200)
    start = len(probe.servo)
    result = GoalRun(probe, action, goal(apply=True, **wave)).result().result
    assert result.from_library and result.applied, result.message
    probe.wait_samples(500)
    t, positions, velocities = probe.trace(start)
    assert max_step_ratio(t, positions, velocities) <= 1.0
    last_period = positions[t > t[-1] - 1.0 / 1.5]
    np.testing.assert_allclose(np.abs(last_period).max(axis=0), np.abs(result.params.amplitude),
                               rtol=0.03)
    waves = []
    probe.node.create_subscription(BodyWaveSpec, 'target_wave', waves.append, LATCHED)
    assert spin_until(probe.executor, lambda: waves, WAIT_S)
    assert waves[-1].frequency_hz == 1.5


def big_library(count: int) -> GaitLibrary:
    gaits = []
    for i in range(count):
        record = gait_record()
        record['wave']['frequency_hz'] = 0.5 + i * 1e-4
        gaits.append(Gait.from_record(record))
    return GaitLibrary(tuple(gaits))


def gait_record() -> dict:
    return {'wave': {'c1': 0.15, 'c2': 1.0, 'k': 8.0, 'frequency_hz': 1.0},
            'geometry': {'l1': 0.08, 'l2': 0.1, 'l3': 0.06, 'r1': 0.02, 'r2': 0.012,
                         'rd1': 0.018, 'rd2': 0.018},
            'params': {'frequency_hz': 1.155, 'amplitude_1': 0.518, 'amplitude_2': -0.6,
                       'w12': -3.1, 'w21': 7.2, 'phi12': 0.3, 'phi21': -2.9, 'alpha': 20.0},
            'loss': 4.1e-4, 'rmse_theta_deg': [0.25, 0.86], 'fitted_at': 'then'}


STORED = 500  # gaits: a save then lasts ~0.5 s on a loaded machine


def saving_started(library_path) -> bool:
    return any(p.name.endswith('.tmp') for p in library_path.parent.iterdir())


def test_killing_the_tuner_while_it_writes_leaves_a_readable_library(
        tuner, probe, library_path):
    # A big library makes every save last long enough to be killed in the middle of one.
    save_library(big_library(STORED), library_path)
    rng = np.random.default_rng(0)
    stored = STORED
    for attempt in range(4):
        process = tuner()
        before = os.stat(library_path).st_mtime_ns
        request = RetuneGait.Request(max_iterations=20, swarm_size=20, seed=attempt)
        request.wave = BodyWaveSpec(c1=0.15, c2=1.0, k=8.0, frequency_hz=1.0 + 0.1 * attempt)
        # A SIGKILLed server lingers in discovery for a while and may take a request for the
        # new one: send again (a fresh client) until the save has begun.
        for _ in range(6):
            service = probe.node.create_client(RetuneGait, 'retune_gait')
            assert spin_until(probe.executor, service.service_is_ready, WAIT_S)
            service.call_async(request)
            if spin_until(probe.executor, lambda: saving_started(library_path), 5.0):
                break
        assert saving_started(library_path)
        # Kill at a random moment of the save (it lasts ~0.5 s).
        spin_until(probe.executor, lambda: False, float(rng.uniform(0.0, 0.4)))
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        library = load_library(library_path)  # readable: the old file or the new one
        assert len(library.gaits) in (stored, stored + 1)
        if os.stat(library_path).st_mtime_ns == before:
            assert len(library.gaits) == stored
        stored = len(library.gaits)


SIMULATED_S = 1234  # a tick far from the wall clock's seconds


def _ticking(probe):
    """Publish /clock at SIMULATED_S every 10 ms of the probe's spin (as fish_sim does)."""
    clock = probe.node.create_publisher(Clock, '/clock', 10)
    tick = Clock()
    tick.clock.sec = SIMULATED_S
    probe.node.create_timer(0.01, lambda: clock.publish(tick))
    return clock


def test_on_simulated_time_a_goal_is_stamped_with_the_clocks_tick(tuner, probe, action):
    clock = _ticking(probe)
    tuner('-p', 'use_sim_time:=true')
    # A goal that arrives before the tuner heard a tick is stamped 0 (no simulated time yet):
    # the tuner's reader matched, then a second of ticks (100) before the goal.
    assert spin_until(probe.executor, lambda: clock.get_subscription_count() > 0, WAIT_S)
    spin_until(probe.executor, lambda: False, 1.0)
    run = GoalRun(probe, action, goal(seed=1, max_iterations=1, swarm_size=4,
                                      use_library=False))
    assert run.handle.accepted
    assert run.handle.stamp.sec == SIMULATED_S, run.handle.stamp


def test_on_simulated_time_the_tuners_ticks_arrive_on_its_clock_node_not_its_own(tuner, probe):
    _ticking(probe)
    tuner('-p', 'use_sim_time:=true')
    namespace = probe.node.get_namespace()

    def topics(by_node, name: str) -> list[str]:
        try:
            return [topic for topic, _types in by_node(name, namespace)]
        except Exception:  # noqa: B902 (rclpy's NodeNameNonExistentError: not discovered yet)
            return []
    subscribed = probe.node.get_subscriber_names_and_types_by_node
    published = probe.node.get_publisher_names_and_types_by_node
    assert spin_until(probe.executor, lambda: '/clock' in topics(subscribed, 'tuner_node_clock'),
                      WAIT_S), topics(subscribed, 'tuner_node_clock')
    assert spin_until(probe.executor, lambda: any(
        topic.endswith('target_wave') for topic in topics(published, 'tuner_node')), WAIT_S)
    assert '/clock' not in topics(subscribed, 'tuner_node')
