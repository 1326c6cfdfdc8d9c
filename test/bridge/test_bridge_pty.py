# SPDX-License-Identifier: Apache-2.0
"""bridge_node and fish_sim as separate processes over a real pty and real DDS."""

import math
import os
import subprocess
import time

from kinematics_probe import stamp_s
import numpy as np
import pytest
from ros_utils import spin_until, stop_process
from sensor_msgs.msg import JointState
from wirefish_bridge.protocol import ServoCommand

pytestmark = pytest.mark.ros
COMMAND_TIMEOUT_S = 1.0  # the bridge's command_timeout_s in the failsafe test
FISH_COMMAND_TIMEOUT_S = 10.0  # the fish's own there: long, so that neutral is the bridge's
NEUTRAL_WAIT_S = 20.0  # wall s: a bound on a stopped bridge, not the failsafe's timing
# Long enough that a burst of frames a starved bridge reads late (stamped at receipt) moves
# the rate little: half a second of them is 3 % of 15 s, where it is 8 % of 6 s.
RATE_WINDOW_S = 15.0


def _stamp(msg) -> float:
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def test_servo_commands_reach_the_fish_and_come_back_measured(
        start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    start_fish(link)
    start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    assert probe.command_until_measured([0.3, -0.2]), probe.servo[-1:]


def test_imu_data_arrives_at_100_hz(start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    start_fish(link)
    start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    probe.imu.clear()
    probe.spin_for(RATE_WINDOW_S)
    stamps = np.array([_stamp(m) for m in probe.imu])
    # The stamps are the bridge's receipt times of a wall-clock fish: on a starved machine the
    # fish writes the frames it owes in a burst, so the first and last stamps alone mislead
    # (615 frames within 5.81 s of stamps, "105.8 Hz", beside two CPU hogs): the rate is the
    # slope of all the stamps against their count.
    rate = 1.0 / np.polyfit(np.arange(len(stamps)), stamps, 1)[0]
    span = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    print(f'imu/data: {len(stamps)} messages, {rate:.2f} Hz (first to last stamp {span:.2f} Hz)')
    assert rate == pytest.approx(100.0, rel=0.05)
    assert probe.imu[-1].header.frame_id == 'imu_link'


def test_bridge_reconnects_each_time_the_fish_reopens_its_device(
        start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    # The bridge first, waiting for the device: its start-up (1-2 s on a loaded machine) must
    # not overlap the fish's first reopen, 1.5 s after its device appears.
    bridge = start_bridge(link, 'reconnect_backoff_max_s:=0.5')
    assert spin_until(probe.executor, lambda: probe.statuses(), 20.0)
    start_fish(link, '--reopen-every', '1.5', '--reopen-count', '5', '--reopen-delay', '0.3')
    assert spin_until(probe.executor, lambda: len(probe.imu) > 0, 20.0)
    assert spin_until(probe.executor, lambda: probe.diagnostics and
                      probe.last_diagnostics()['reconnects'] == '5', 20.0), \
        str(probe.last_diagnostics())
    probe.spin_for(1.5)
    stamps = [_stamp(m) for m in probe.imu]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))[-5:]
    diagnostics = probe.last_diagnostics()
    print(f'five longest imu gaps {gaps}; diagnostics {diagnostics}')
    assert bridge.poll() is None
    assert diagnostics['reconnects'] == '5' and diagnostics['link_state'] == 'connected'
    assert max(gaps) < 0.3 + 2.0  # device absent 0.3 s, reconnected within 2 s


def test_corrupted_bytes_are_counted_and_never_published(
        start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    # A perfect IMU on a fish at rest: every valid telemetry carries exactly known values.
    start_fish(link, '--corrupt-fraction', '0.05', '--imu-noise-scale', '0')
    start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 0, 20.0)
    probe.spin_for(5.0)
    diagnostics = probe.last_diagnostics()
    print(f'{len(probe.imu)} imu/data in ~5 s; diagnostics {diagnostics}')
    assert len(probe.imu) >= 5
    assert int(diagnostics['crc_errors']) > 0
    for msg in probe.imu:
        assert (msg.orientation.x, msg.orientation.y, msg.orientation.z,
                msg.orientation.w) == (0.0, 0.0, 0.0, 1.0)
        assert (msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z) == (
            0.0, 0.0, 0.0)
        assert (msg.linear_acceleration.x, msg.linear_acceleration.y) == (0.0, 0.0)
        assert msg.linear_acceleration.z == pytest.approx(9.80665, abs=1e-5)
    assert all(m.position.tolist() == [0.0, 0.0] for m in probe.servo)


def test_bridge_commands_neutral_when_servo_cmd_stops(start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    # The firmware's own timeout is long, so neutral here comes from the bridge. Its timeout is
    # the wall clock's: 1 s, so that the probe's own commands, held up beside two CPU hogs,
    # keep it out of failsafe while they stream (at 0.3 s it went neutral mid-stream there).
    start_fish(link, '--command-timeout', f'{FISH_COMMAND_TIMEOUT_S:g}')
    start_bridge(link, f'command_timeout_s:={COMMAND_TIMEOUT_S}')
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    assert probe.command_until_measured([0.4, 0.3]), probe.servo[-1:]
    last_command = probe.last_command_s
    probe.servo.clear()

    def neutral_stamps() -> list[float]:
        return [_stamp(m) for m in probe.servo if max(map(abs, m.position)) < 1e-3]

    # Until servo_state reads neutral: the bridge stamps it when the fish's telemetry arrives,
    # so a probe the loaded machine holds up (it may hear nothing for seconds) still judges
    # the bridge's time, not its own.
    assert spin_until(probe.executor, lambda: neutral_stamps(), NEUTRAL_WAIT_S), \
        f'servo_state never neutral in {NEUTRAL_WAIT_S:g} s: {probe.servo[-1:]}'
    delay = neutral_stamps()[0] - last_command
    print(f'neutral measured {delay:.3f} s after the last servo_cmd')
    # The claim is whose timeout it is: the bridge's, never before it, long before the fish's.
    # How soon after it the gate commands neutral is the gate's unit test (one tick, injected
    # time); here the servos' travel and a loaded machine's scheduling add up to half a second.
    assert COMMAND_TIMEOUT_S <= delay < FISH_COMMAND_TIMEOUT_S / 2
    # /diagnostics comes once a second: it says so by the next one.
    assert spin_until(probe.executor, lambda: bool(probe.statuses()) and
                      probe.last_diagnostics().get('failsafe') == 'True', 5.0), \
        probe.statuses()[-1:]


def test_bridge_and_fish_exit_cleanly_on_sigint(start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    fish = start_fish(link)
    bridge = start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    assert stop_process(bridge) == 0
    assert stop_process(fish) == 0
    assert not os.path.lexists(link) and not os.path.lexists(f'{link}.owner')
    assert math.isfinite(_stamp(probe.imu[-1]))


def test_invalid_parameter_is_refused_with_a_reason_and_a_valid_one_applies(
        start_fish, start_bridge, probe, tmp_path):
    from rclpy.parameter import Parameter
    link = tmp_path / 'tty'
    start_fish(link)
    start_bridge(link)
    (refused,) = probe.set_parameters('bridge_node',
                                      [Parameter('command_timeout_s', value=-1.0)])
    assert not refused.successful and 'command_timeout_s' in refused.reason
    (backoff,) = probe.set_parameters('bridge_node',
                                      [Parameter('reconnect_backoff_max_s', value=0.05)])
    assert not backoff.successful and 'reconnect_backoff' in backoff.reason
    (applied,) = probe.set_parameters('bridge_node',
                                      [Parameter('imu_frame_id', value='imu_test')])
    assert applied.successful
    assert spin_until(probe.executor,
                      lambda: probe.imu and probe.imu[-1].header.frame_id == 'imu_test', 10.0)


def test_fish_sim_publishes_ground_truth_of_a_fish_swimming_on_bridge_commands(
        start_fish, start_bridge, probe, tmp_path):
    from nav_msgs.msg import Odometry
    truth = []
    probe.node.create_subscription(Odometry, 'sim/ground_truth', truth.append, 10)
    link = tmp_path / 'tty'
    start_fish(link, '--ros')
    start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10 and truth, 20.0)
    start = time.monotonic()
    deadline = start + 3.0
    while time.monotonic() < deadline:   # a 3 Hz beat of both servos
        phase = 2 * math.pi * 3.0 * (time.monotonic() - start)
        probe.cmd.publish(JointState(name=['servo_1', 'servo_2'],
                                     position=[0.38 * math.cos(phase),
                                               0.47 * math.cos(phase + 1.0)]))
        probe.executor.spin_once(timeout_sec=0.005)
    last = truth[-1]
    # The speed over the last second, not the last sample's: U swings within a beat, and this
    # command stream is paced by a probe that a slow host starves (one sample read 0.044 m/s
    # where the fish had swum 0.93 m in the 3 s).
    end = stamp_s(last)
    recent = [m.twist.twist.linear.x for m in truth if stamp_s(m) >= end - 1.0]
    mean_u = sum(recent) / len(recent)
    print(f'ground truth after 3 s: U = {mean_u:.3f} m/s over the last second '
          f'({len(recent)} samples; the last {last.twist.twist.linear.x:.3f}), '
          f'x = {last.pose.pose.position.x:.3f} m')
    assert (last.header.frame_id, last.child_frame_id) == ('odom', 'base_link')
    assert mean_u > 0.1 and last.pose.pose.position.x > 0.1


def test_dropped_frames_are_counted_as_sequence_gaps(start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    start_fish(link, '--drop-fraction', '0.2')
    start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    probe.spin_for(3.0)
    diagnostics = probe.last_diagnostics()
    print(f'drop 20 %: {diagnostics["drops"]} gaps, {diagnostics["frames_in"]} frames in')
    drops, frames = int(diagnostics['drops']), int(diagnostics['frames_in'])
    assert drops / (drops + frames) == pytest.approx(0.2, abs=0.07)
    assert diagnostics['crc_errors'] == '0'


def test_a_stalled_fish_shows_as_a_gap_and_the_stream_resumes(
        start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    start_fish(link, '--stall-every', '2.5', '--stall-for', '1.0')
    bridge = start_bridge(link)
    assert spin_until(probe.executor, lambda: len(probe.imu) > 10, 20.0)
    probe.spin_for(4.0)
    stamps = [_stamp(m) for m in probe.imu]
    longest = max(b - a for a, b in zip(stamps, stamps[1:]))
    print(f'longest imu gap during stalls of 1 s: {longest:.3f} s')
    assert 0.9 < longest < 1.3
    assert bridge.poll() is None
    assert probe.last_diagnostics()['link_state'] == 'connected'


def test_bridge_commands_neutral_as_it_shuts_down(start_bridge, probe, fake_device):
    # This test plays the fish: it holds the pty's master side and decodes what arrives.
    bridge = start_bridge(fake_device.link)
    commands = []
    deadline = time.monotonic() + 20.0
    while not any(c == pytest.approx((0.4, 0.3), abs=1e-6) for c in commands):
        assert time.monotonic() < deadline, 'no servo command reached the fish'
        fake_device.send_fish_heartbeat()
        probe.spin_for(0.05, command=[0.4, 0.3])
        commands += [(m.servo_1, m.servo_2) for m in fake_device.messages()
                     if isinstance(m, ServoCommand)]
    assert stop_process(bridge) == 0
    commands += [(m.servo_1, m.servo_2) for m in fake_device.messages()
                 if isinstance(m, ServoCommand)]
    assert commands[-1] == (0.0, 0.0)


@pytest.mark.parametrize('flag, value, reason', [
    ('--telemetry-hz', '0', '--telemetry-hz must be finite and > 0'),
    ('--ground-truth-hz', 'nan', '--ground-truth-hz must be finite and > 0'),
    ('--corrupt-fraction', '1.5', '--corrupt-fraction must be in [0, 1]'),
    ('--servo-rate-limit', '-2', 'rate_limit_rad_s must be finite and > 0'),
])
def test_fish_sim_refuses_bad_flags_with_one_line(fish_sim_exe, tmp_path, ros_env, flag, value,
                                                  reason):
    result = subprocess.run([str(fish_sim_exe), '--link', str(tmp_path / 'tty'), flag,
                             value], env=ros_env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert reason in result.stderr and 'Traceback' not in result.stderr, result.stderr
    assert not (tmp_path / 'tty').exists()
