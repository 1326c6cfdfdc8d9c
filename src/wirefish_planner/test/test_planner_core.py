# SPDX-License-Identifier: Apache-2.0
"""The planner's rules (modes, timeouts, refusals) and its loops on an in-process fish."""

import math

import numpy as np
import pytest
from wirefish_planner.planner_config import (command_targets, cpg_topic, cpg_values,
                                             values_changed)
from wirefish_planner.planner_core import command_problem, ignored_fields
from wirefish_sim.faults import Disturbance


def _imu(planner, t0, seconds, yaw=0.0, rate=0.0, command=None):
    """Feed IMU samples at 100 Hz (and ``command`` (speed, yaw rate) at 20 Hz)."""
    for i in range(int(seconds * 100)):
        t = t0 + i * 0.01
        if command is not None and i % 5 == 0:
            planner.command(t, *command)
        planner.imu(t, t, yaw + rate * i * 0.01, rate)


def test_the_fish_rests_before_any_cmd_vel(make_planner):
    out = make_planner().step(1.0)
    assert out.mode == 'rest' and out.gait.point is None
    assert cpg_values(out) == {'amplitude_1': 0.0, 'amplitude_2': 0.0, 'offset_1': 0.0,
                               'offset_2': 0.0}


@pytest.mark.parametrize('speed, rate', [(-0.1, 0.0), (math.nan, 0.0), (0.1, math.inf)])
def test_a_refused_command_changes_nothing(make_planner, speed, rate):
    planner = make_planner()
    planner.command(0.0, 0.2, 0.0)
    assert planner.command(0.1, speed, rate) == command_problem(speed, rate) is not None
    assert planner.step(0.2).gait.target_speed == 0.2


def test_negative_speed_says_why():
    assert 'backwards' in command_problem(-0.1, 0.0)


def test_other_twist_fields_are_named():
    assert ignored_fields((0.1, 0.2, 0.0), (0.0, 0.3, 0.5)) == ['linear.y', 'angular.y']


def test_cmd_vel_timeout_rests_and_releases_the_hold(make_planner):
    planner = make_planner(cmd_vel_timeout_s=0.5)
    planner.command(0.0, 0.2, 0.0)
    _imu(planner, 0.0, 0.4, yaw=0.3)
    assert planner.step(0.4).mode == 'hold'
    out = planner.step(0.51)
    assert out.mode == 'rest' and math.isnan(out.heading_target) and out.offset == 0.0


def test_a_planner_that_slept_reads_its_queue_before_it_rests(make_planner):
    planner = make_planner(cmd_vel_timeout_s=0.5, imu_timeout_s=0.5)
    planner.command(0.0, 0.2, 0.0)
    _imu(planner, 0.0, 0.4, yaw=0.3)
    target = planner.step(0.4).heading_target
    asleep = planner.step(1.2)  # 0.8 s late: the cmd_vel and IMU of that time still queued
    planner.command(1.2, 0.2, 0.0)
    _imu(planner, 1.2, 0.05, yaw=0.3)
    awake = planner.step(1.25)
    assert asleep.mode == awake.mode == 'hold'
    assert awake.heading_target == pytest.approx(target)


def test_a_late_step_defers_a_real_timeout_by_one_step(make_planner):
    planner = make_planner(cmd_vel_timeout_s=0.5)
    planner.command(0.0, 0.2, 0.0)
    _imu(planner, 0.0, 0.4, yaw=0.3)
    planner.step(0.4)
    assert planner.step(1.2).mode == 'hold'
    assert planner.step(1.25).mode == 'rest'


def test_the_heading_is_latched_when_the_turn_command_ends(make_planner):
    planner = make_planner()
    _imu(planner, 0.0, 2.0, yaw=0.0, rate=0.2, command=(0.2, 0.2))  # turning at 0.2 rad/s
    assert planner.step(2.0).mode == 'turn'
    planner.command(2.0, 0.2, 0.0)
    out = planner.step(2.0)
    assert out.mode == 'hold'
    assert out.heading_target == pytest.approx(0.2 * 1.99, abs=0.02)  # the yaw at the end


def test_turning_at_speed_zero_rests_and_says_why(make_planner):
    planner = make_planner()
    planner.command(0.0, 0.0, 0.3)
    out = planner.step(0.1)
    assert out.mode == 'rest' and 'forward speed' in out.note


def test_without_imu_the_turn_is_open_loop(make_planner):
    planner = make_planner(imu_timeout_s=0.5)
    planner.command(0.0, 0.2, 0.2)
    out = planner.step(0.1)
    assert out.mode == 'open_loop'
    assert out.offset == pytest.approx(0.2 / (planner.pi.gains.turn_gain * 0.2))


def test_switching_the_hold_off_releases_the_latched_heading(make_planner):
    planner = make_planner()
    planner.command(0.0, 0.2, 0.0)
    _imu(planner, 0.0, 0.3)
    planner.reconfigure(make_planner(heading_hold=False))
    planner.command(0.3, 0.2, 0.0)
    out = planner.step(0.3)
    assert out.mode == 'straight' and math.isnan(out.heading_target)


def test_offset_changes_inside_the_deadband_are_not_sent():
    sent = {'offset_1': 0.1, 'offset_2': 0.1}
    assert not values_changed(sent, {'offset_1': 0.1005, 'offset_2': 0.1005})
    assert values_changed(sent, {'offset_1': 0.11, 'offset_2': 0.11})
    assert values_changed(sent, {'offset_1': 0.0, 'offset_2': 0.0})  # rest is exact


def test_a_rest_command_keeps_what_the_cpg_runs_and_waits_to_know_it(make_planner):
    rest = cpg_values(make_planner().step(1.0))
    assert command_targets(rest, None) is None
    running = {'frequency_hz': 1.3, 'amplitude_1': 0.3, 'amplitude_2': 0.4, 'offset_1': 0.1,
               'offset_2': 0.1, 'w12': -0.4, 'w21': 0.6, 'phi12': 1.7, 'phi21': 1.0,
               'alpha': 20.0}
    assert command_targets(rest, running) == dict(running, amplitude_1=0.0, amplitude_2=0.0,
                                                  offset_1=0.0, offset_2=0.0)


def test_a_gait_command_names_every_target(make_planner):
    planner = make_planner()
    planner.command(0.0, 0.2, 0.0)
    wanted = cpg_values(planner.step(0.05))
    assert command_targets(wanted, None) == wanted and len(wanted) == 10


@pytest.mark.parametrize('name, topic', [
    ('cpg_node', 'cpg_command'), ('/cpg_node', '/cpg_command'),
    ('/fish_2/cpg_node', '/fish_2/cpg_command'), ('sub/cpg_node', 'sub/cpg_command')])
def test_the_command_topic_is_in_the_cpg_nodes_namespace(name, topic):
    assert cpg_topic(name, 'cpg_command') == topic


@pytest.fixture(scope='module')
def turn_and_hold(closed_loop):
    """One in-process drive with a 0.05 rad/s current: straight, left, right, straight."""
    from wirefish_planner.planner_config import planner_from
    from wirefish_planner.planner_node_parameters import TABLE

    leg = closed_loop.Leg
    legs = [leg(6.0, 0.2), leg(8.0, 0.2, 0.2), leg(8.0, 0.2, -0.2), leg(16.0, 0.2)]
    return closed_loop.run_legs(planner_from(TABLE.defaults()), legs,
                                Disturbance(yaw_rate_rad_s=0.05))


@pytest.mark.parametrize('rate, start', [(0.2, 10.0), (-0.2, 18.0)])
def test_in_process_yaw_rate_follows_its_setpoint(turn_and_hold, rate, start):
    tr = turn_and_hold
    window = (tr.t >= start) & (tr.t < start + 4.0)
    assert tr.yaw_rate[window].mean() == pytest.approx(rate, rel=0.2)


def test_in_process_heading_hold_rejects_the_current(turn_and_hold, closed_loop):
    tr = turn_and_hold
    latched = tr.yaw[np.searchsorted(tr.t, 22.0)]
    window = (tr.t >= 27.0)
    assert closed_loop.heading_rms_deg(tr.yaw[window], latched) < 3.0


def test_in_process_servo_commands_never_step(turn_and_hold):
    rates = np.abs(np.diff(turn_and_hold.servo, axis=0)) / 0.005
    assert rates.max() < 9.1  # the virtual fish's slew limit: never a jump


def test_the_default_turn_gain_is_what_the_in_process_fish_identifies(turn_and_hold):
    from wirefish_planner.planner_node_parameters import TABLE
    from wirefish_planner.yaw_control import identify_turn_gain, steady_means

    tr = turn_and_hold
    gain, bias = identify_turn_gain(*steady_means(tr.t, tr.speed, tr.offset, tr.yaw_rate))
    assert gain == pytest.approx(TABLE.defaults()['turn_gain'], rel=0.15)
    assert bias == pytest.approx(0.05, abs=0.02)  # the current
