# SPDX-License-Identifier: Apache-2.0
"""cpg_node as a separate process: servo stream, parameters, start/stop, clamping."""

import math

from cpg_probe import CPG_NODE, max_step_ratio, WAIT_S
import numpy as np
import pytest
from ros_utils import spin_until, stop_process
from std_srvs.srv import Trigger

# It mostly waits (0.21 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]


def test_servo_cmd_streams_both_servos_and_converges_to_the_table1_amplitudes(spawn, probe):
    spawn([CPG_NODE])
    probe.wait_samples(300)  # 3 s at the default 100 Hz
    t, positions, velocities = probe.trace()
    assert probe.servo[-1].name == ['servo_1', 'servo_2']
    assert np.all(np.diff(t) > 0)
    last_period = positions[t > t[-1] - 1.0]
    np.testing.assert_allclose(np.abs(last_period).max(axis=0), [0.38, 0.47], rtol=0.02)
    assert np.abs(velocities).max() > 1.0  # a live, moving command


def test_cpg_params_is_latched_for_a_late_subscriber(spawn, probe):
    spawn([CPG_NODE])
    probe.wait_samples(20)
    assert spin_until(probe.executor, lambda: probe.cpg_params, WAIT_S)
    msg = probe.cpg_params[-1]
    assert (msg.frequency_hz, msg.w12, msg.w21, msg.phi12, msg.phi21) == (
        1.0, -0.41, 0.64, 1.76, 1.06)
    assert list(msg.amplitude) == [0.38, 0.47]


INVALID_UPDATES = [
    {'amplitude_1': math.nan},
    {'frequency_hz': 0.0},
    {'w12': 50.0},
    {'phi21': -math.inf},
    {'integration_step_s': 1.0},
    {'amplitude_1': 0.2, 'alpha': -1.0},  # atomic: the valid half must not apply either
]


def test_invalid_updates_are_rejected_with_a_reason_and_change_nothing(spawn, probe):
    spawn([CPG_NODE])
    probe.wait_samples(20)
    names = ['frequency_hz', 'amplitude_1', 'w12', 'phi21', 'alpha', 'integration_step_s']
    before = probe.get_parameters(names)
    # The latched announcement can arrive after the samples (seen once in a full run): count
    # from it, so that only an announcement the invalid updates caused is counted.
    assert spin_until(probe.executor, lambda: probe.cpg_params, WAIT_S)
    published = len(probe.cpg_params)
    for update in INVALID_UPDATES:
        result = probe.set_parameters(update)
        assert not result.successful, update
        assert result.reason, update
    assert probe.get_parameters(names) == before
    probe.wait_samples(20)
    assert len(probe.cpg_params) == published  # no new parameters were announced


def test_valid_update_applies_smoothly_and_is_announced(spawn, probe):
    spawn([CPG_NODE])
    probe.wait_samples(150)
    start = len(probe.servo)
    result = probe.set_parameters({'amplitude_1': 0.2, 'amplitude_2': -0.3,
                                   'frequency_hz': 1.5, 'offset_1': 0.1})
    assert result.successful, result.reason
    probe.wait_samples(250)
    t, positions, velocities = probe.trace(start - 50)
    assert max_step_ratio(t, positions, velocities) <= 1.0
    last_period = positions[t > t[-1] - 1.0 / 1.5]
    np.testing.assert_allclose(last_period.max(axis=0) - last_period.min(axis=0),
                               [0.4, 0.6], rtol=0.03)
    assert spin_until(probe.executor, lambda: probe.cpg_params[-1].frequency_hz == 1.5,
                      WAIT_S)
    assert list(probe.cpg_params[-1].amplitude) == [0.2, -0.3]


def test_stop_brings_the_tail_to_rest_without_a_step_and_start_resumes(spawn, probe):
    spawn([CPG_NODE])
    probe.wait_samples(150)
    start = len(probe.servo)
    stop = probe.node.create_client(Trigger, 'stop')
    assert probe.call(stop, Trigger.Request()).success
    probe.wait_samples(150)
    t, positions, velocities = probe.trace(start - 25)
    assert max_step_ratio(t, positions, velocities) <= 1.0
    assert np.abs(positions[-10:]).max() < 1e-3
    # cpg_params says what runs: at rest while stopped (a gait-mode board swims what it says).
    assert list(probe.cpg_params[-1].amplitude) == [0.0, 0.0]
    assert probe.cpg_params[-1].frequency_hz == 1.0
    begin = probe.node.create_client(Trigger, 'start')
    assert probe.call(begin, Trigger.Request()).success
    probe.wait_samples(200)
    assert list(probe.cpg_params[-1].amplitude) == pytest.approx([0.38, 0.47])
    t, positions, velocities = probe.trace(start + 100)
    assert max_step_ratio(t, positions, velocities) <= 1.0
    assert np.abs(positions[-100:, 1]).max() == pytest.approx(0.47, rel=0.03)


def test_outputs_beyond_the_servo_limit_are_clamped_with_a_warning(spawn, probe):
    proc = spawn([CPG_NODE, '--ros-args', '-p', 'servo_limit_rad:=0.3'])
    probe.wait_samples(200)
    _, positions, _ = probe.trace()
    assert np.abs(positions).max() <= 0.3
    assert np.isclose(np.abs(positions[:, 1]).max(), 0.3)
    stop_process(proc)
    assert 'clamped' in proc.stdout.read()


def test_autostart_false_holds_still_until_start(spawn, probe):
    spawn([CPG_NODE, '--ros-args', '-p', 'autostart:=false'])
    probe.wait_samples(50)
    _, positions, _ = probe.trace()
    assert np.abs(positions).max() == 0.0
    assert probe.cpg_params and all(list(p.amplitude) == [0.0, 0.0] for p in probe.cpg_params)
    begin = probe.node.create_client(Trigger, 'start')
    assert probe.call(begin, Trigger.Request()).success
    probe.wait_samples(200)
    assert np.abs(probe.trace()[1][-50:]).max() > 0.3


def test_servo_cmd_is_stamped_with_simulated_time_when_use_sim_time(spawn, probe):
    from builtin_interfaces.msg import Time
    from rosgraph_msgs.msg import Clock
    spawn([CPG_NODE, '--ros-args', '-p', 'use_sim_time:=true'])
    clock_pub = probe.node.create_publisher(Clock, '/clock', 10)
    sim_ns = [1000 * 10**9]

    def tick() -> None:
        sim_ns[0] += 5_000_000  # 5 ms of simulated time per tick
        clock_pub.publish(Clock(clock=Time(sec=sim_ns[0] // 10**9,
                                           nanosec=sim_ns[0] % 10**9)))
    probe.node.create_timer(0.005, tick)
    probe.wait_samples(100)
    t, positions, _ = probe.trace()
    assert t.min() >= 1000.0 and t.max() <= sim_ns[0] * 1e-9
    assert np.abs(positions).max() > 0.1  # it oscillates on simulated time
