# SPDX-License-Identifier: Apache-2.0
"""kinematics_node as a separate process: servo samples in, body wave and speed estimate out."""

import math

from kinematics_probe import locked_servo, ORIGIN_S, stamp_s
import numpy as np
import pytest
from ros_utils import stop_process
from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.tail_beat import estimate_speed_over
from wirefish_kinematics.wire_coupling import bend_angles

# It mostly waits (0.11 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]
G = FishGeometry()
POSE_A = (0.3, -0.2)
POSE_B = (-0.1, 0.4)
BEAT_HZ = 1.7  # a beat whose period does not divide the node's history span


def core_wave(angles, stations: int = 50, geometry: FishGeometry = G):
    """Return (q, x, y, beta1, beta2, theta1, theta2) of the pure core for servo angles."""
    q = np.linspace(0.0, geometry.tail_length, stations)
    beta1, beta2 = (float(b) for b in bend_angles(*angles, geometry))
    x, y = body_positions(q, beta1, beta2, geometry)
    theta1, theta2 = swing_angles(beta1, beta2, geometry)
    return q, x, y, beta1, beta2, float(theta1), float(theta2)


def send_pose_until_seen(probe, pose, first_index: int, topic: str = 'servo_cmd') -> int:
    """Stream a still pose until a body_wave of it arrives; return the next sample index."""
    beta1 = float(bend_angles(*pose, G)[0])
    index = first_index

    def seen() -> bool:
        nonlocal index
        probe.send(index, pose, topic=topic)
        index += 1
        probe.spin(0.02)
        return bool(probe.body) and probe.body[-1].beta1 == beta1

    probe.wait_for(seen, f'a body_wave of pose {pose}')
    return index


def hold_pose_until(probe, pose, first_index: int, done, what: str) -> None:
    """Keep streaming a still pose (10 ms of sample time apart) until ``done()``."""
    index = first_index

    def sent_and_done() -> bool:
        nonlocal index
        probe.send(index, pose)
        index += 1
        probe.spin(0.01)
        return done()

    probe.wait_for(sent_and_done, what)


def test_body_wave_and_markers_equal_the_core_for_a_pose(start_node, probe):
    start_node()
    probe.wait_connected()
    index = send_pose_until_seen(probe, POSE_A, 0)
    msg = probe.body[-1]
    q, x, y, beta1, beta2, theta1, theta2 = core_wave(POSE_A)
    assert msg.header.frame_id == 'tail_base'
    assert msg.header.stamp.sec == ORIGIN_S  # stamped with the sample it shows
    np.testing.assert_allclose(msg.q, q, rtol=0, atol=1e-15)
    np.testing.assert_allclose(msg.x, x, rtol=0, atol=1e-15)
    np.testing.assert_allclose(msg.y, y, rtol=0, atol=1e-15)
    assert (msg.beta1, msg.beta2) == (beta1, beta2)
    assert (msg.theta1, msg.theta2) == pytest.approx((theta1, theta2), abs=1e-15)
    assert list(msg.y_desired) == []  # no tail beat yet: the overlay has no phase
    # Markers go out with every 5th body_wave; the first ones may come before the probe's
    # reliable subscription has matched (seen once in a full run): the pose is held until they
    # arrive.
    hold_pose_until(probe, POSE_A, index, lambda: probe.markers, 'body_wave_markers')
    markers = {m.id: m for m in probe.markers[-1].markers}
    assert all(m.header.frame_id == 'tail_base' for m in markers.values())
    tail = markers[0]
    np.testing.assert_allclose([p.y for p in tail.points], y, rtol=0, atol=1e-15)
    ends_x, ends_y = body_positions(np.array(G.link_end_stations), beta1, beta2, G)
    assert (markers[2].points[0].x, markers[2].points[0].y) == pytest.approx(
        (ends_x[0], ends_y[0]), abs=1e-15)
    assert (markers[3].points[0].x, markers[3].points[0].y) == pytest.approx(
        (ends_x[1], ends_y[1]), abs=1e-15)


def test_speed_estimate_equals_the_core_over_the_last_tail_beat(start_node, probe):
    start_node('-p', 'station_count:=4')
    probe.publish_target(0.3, 0.0, 5.0, 2.0)
    probe.wait_connected()
    index = 0

    def estimates(count: int):
        def enough() -> bool:
            nonlocal index
            angles, rates = locked_servo(index * 0.01, 2.0)
            probe.send(index, angles, rates)
            index += 1
            probe.spin(0.01)
            return len(probe.speed) >= count
        return enough

    probe.wait_for(estimates(2), 'two speed estimates')
    msg = probe.speed[-1]
    end = stamp_s(msg)
    start = end - 1.0 / msg.tail_beat_hz
    t = np.array([s[0] for s in probe.sent])
    angles = np.array([s[1] for s in probe.sent])
    rates = np.array([s[2] for s in probe.sent])
    core = estimate_speed_over(t, angles, rates, start, end, G)
    assert msg.tail_beat_hz == pytest.approx(2.0, rel=1e-3)
    for name in ('speed', 'thrust', 'drag', 'swimming_number', 'tail_beat_hz',
                 'tail_tip_amplitude'):
        assert getattr(msg, name) == pytest.approx(getattr(core, name), rel=1e-6), name
    # The desired wave (target_wave: envelope 0.3 q) is shown in phase with the tail at q1.
    wave = probe.body[-1]
    q1 = wave.q[1]
    assert q1 == pytest.approx(G.l1, rel=1e-12)
    assert len(wave.y_desired) == 4 and wave.y_desired[0] == 0.0
    assert np.all(np.abs(wave.y_desired) <= 0.3 * np.array(wave.q) + 1e-12)
    beta = bend_angles(angles[:, 0], angles[:, 1], G)
    y_q1 = body_positions(np.array([q1]), *beta, G)[1][:, 0]
    half_range = 0.5 * np.ptp(y_q1)
    assert wave.y_desired[1] / (0.3 * q1) == pytest.approx(wave.y[1] / half_range, abs=0.1)


def test_one_speed_estimate_per_tail_beat(start_node, probe):
    start_node('-p', 'station_count:=4')
    probe.wait_connected()
    index = 0

    def six_estimates() -> bool:
        nonlocal index
        angles, rates = locked_servo(index * 0.01, BEAT_HZ)
        probe.send(index, angles, rates)
        index += 1
        probe.spin(0.005)
        return len(probe.speed) >= 6

    probe.wait_for(six_estimates, 'six speed estimates')
    ends = np.array([stamp_s(msg) for msg in probe.speed])
    # Consecutive estimates end one beat apart: none repeated for the same beat, although the
    # history (not a whole number of beats long) moves its crossings by a few ms.
    np.testing.assert_allclose(np.diff(ends), 1.0 / BEAT_HZ, atol=0.02)


def test_a_tail_at_rest_reports_zero_speed(start_node, probe):
    start_node('-p', 'max_tail_beat_period_s:=0.3')
    probe.wait_connected()
    index = send_pose_until_seen(probe, POSE_A, 0)
    hold_pose_until(probe, POSE_A, index, lambda: bool(probe.speed), 'a speed estimate at rest')
    msg = probe.speed[-1]
    assert (msg.speed, msg.thrust, msg.drag, msg.tail_beat_hz) == (0.0, 0.0, 0.0, 0.0)


BAD_SAMPLES = [
    {'angles': (math.nan, 0.1)},
    {'angles': (0.1, math.inf)},
    {'angles': (0.1, 0.2), 'rates': (math.nan, 0.0)},
    {'angles': (0.1, 0.2), 'names': ('joint_a', 'joint_b')},
    {'angles': (0.1, 0.2), 'names': ()},  # unnamed positions: refused (servo_joints)
    {'angles': (0.1,), 'rates': (0.0,), 'names': ('servo_1',)},
    {'angles': (0.1, 0.2), 'names': ('servo_1', 'servo_2', 'third_joint_without_position')},
]


def test_bad_samples_are_dropped_with_a_warning_and_the_node_keeps_running(start_node, probe):
    proc = start_node()
    probe.wait_connected()
    index = send_pose_until_seen(probe, POSE_A, 0)
    count = len(probe.body)
    for bad in BAD_SAMPLES:
        probe.send(index, **bad)
        index += 1
        probe.spin(0.05)
    probe.spin(0.3)
    assert len(probe.body) == count  # nothing new was computed from the bad samples
    assert proc.poll() is None
    send_pose_until_seen(probe, POSE_B, index)
    assert probe.body[-1].beta2 == float(bend_angles(*POSE_B, G)[1])
    assert stop_process(proc) == 0
    output = proc.stdout.read()
    assert 'sample dropped' in output
    assert 'non-finite servo angles' in output
    assert "JointState needs joints ('servo_1', 'servo_2')" in output
    assert 'non-finite servo rates' in output
    assert 'JointState has 2 positions for 3 names' in output


INVALID_UPDATES = [
    {'l1': 0.0},
    {'r2': -0.01},
    {'drag_coefficient': math.nan},
    {'wetted_area': math.inf},
    {'station_count': 1},
    {'wave_frequency_hz': 0.0},
    {'l3': 0.05, 'rd1': 0.0},  # atomic: the valid half must not apply either
]


def test_invalid_parameters_are_rejected_with_a_reason_and_change_nothing(start_node, probe):
    start_node()
    probe.wait_connected()
    index = send_pose_until_seen(probe, POSE_A, 0)
    names = ['l1', 'l3', 'r2', 'rd1', 'drag_coefficient', 'wetted_area', 'station_count']
    before = probe.get_parameters(names)
    for update in INVALID_UPDATES:
        result = probe.set_parameters(update)
        assert not result.successful, update
        assert result.reason, update
    assert probe.get_parameters(names) == before
    index = send_pose_until_seen(probe, POSE_B, index)
    assert probe.body[-1].x == pytest.approx(core_wave(POSE_B)[1].tolist(), abs=1e-15)
    # a valid update applies to the next body wave
    result = probe.set_parameters({'l3': 0.05, 'station_count': 10})
    assert result.successful, result.reason
    geometry = FishGeometry(l3=0.05)

    def updated() -> bool:
        nonlocal index
        probe.send(index, POSE_B)
        index += 1
        probe.spin(0.02)
        return len(probe.body[-1].q) == 10

    probe.wait_for(updated, 'a body_wave with the new parameters')
    np.testing.assert_allclose(probe.body[-1].y, core_wave(POSE_B, 10, geometry)[2],
                               rtol=0, atol=1e-15)


def test_use_servo_state_switches_to_the_measured_angles_and_back(start_node, probe):
    start_node('-p', 'use_servo_state:=true')
    probe.wait_connected('servo_state')
    assert probe.publishers['servo_cmd'].get_subscription_count() == 0
    index = send_pose_until_seen(probe, POSE_B, 0, topic='servo_state')
    result = probe.set_parameters({'use_servo_state': False})
    assert result.successful, result.reason
    probe.wait_connected('servo_cmd')
    send_pose_until_seen(probe, POSE_A, index, topic='servo_cmd')
    probe.wait_for(lambda: probe.publishers['servo_state'].get_subscription_count() == 0,
                   'servo_state to be unsubscribed')


def test_markers_reach_a_reliable_subscriber_like_rviz(start_node, probe):
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from visualization_msgs.msg import MarkerArray
    received = []
    probe.node.create_subscription(MarkerArray, 'body_wave_markers', received.append,
                                   QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    start_node()
    probe.wait_connected()
    index = send_pose_until_seen(probe, POSE_A, 0)
    hold_pose_until(probe, POSE_A, index, lambda: bool(received),
                    'body_wave_markers on a reliable subscription')
    assert {m.id for m in received[-1].markers} >= {0, 2, 3}
