# SPDX-License-Identifier: Apache-2.0
"""The telemetry limits table: each field judged against its physical range."""

import dataclasses
import math

import numpy as np
import pytest
from wirefish_bridge.protocol import Status, Telemetry, TelemetryCompact
from wirefish_bridge.telemetry_limits import LIMITS, telemetry_problem

AT_REST = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                    accel=(0.0, 0.0, 9.81), servo_1=0.0, servo_2=0.0, battery_v=8.2, status=0)


def test_a_fish_at_rest_is_possible():
    assert telemetry_problem(AT_REST) is None


@pytest.mark.parametrize('change, field', [
    ({'roll': 3.4e38}, 'roll'), ({'roll': -3.2}, 'roll'), ({'pitch': 1.6}, 'pitch'),
    ({'yaw': math.tau}, 'yaw'), ({'gyro': (0.0, 0.0, 40.0)}, 'gyro.z'),
    ({'accel': (-200.0, 0.0, 9.81)}, 'accel.x'), ({'servo_1': 1.8}, 'servo_1'),
    ({'servo_2': -1e6}, 'servo_2'), ({'battery_v': -0.1}, 'battery_v'),
    ({'battery_v': 12.6}, 'battery_v'), ({'status': 0x0400}, 'undefined bits'),
    ({'status': 0x0040}, 'outside gait mode'), ({'status': 0x0080}, 'outside gait mode'),
    ({'status': 0x01C0, 'gait_id': 2}, 'at once'), ({'status': 0x0100}, 'gait_id 0'),
    ({'gait_id': 4}, 'gait_id 4'),
])
def test_each_impossible_field_is_named(change, field):
    problem = telemetry_problem(dataclasses.replace(AT_REST, **change))
    assert problem is not None and field in problem


@pytest.mark.parametrize('change', [
    {'roll': float(np.float32(math.pi))}, {'yaw': float(np.float32(-math.pi))},
    {'pitch': float(np.float32(math.pi / 2))}, {'gyro': (34.9, -34.9, 0.0)},
    {'accel': (0.0, 0.0, 156.0)}, {'servo_1': math.pi / 2, 'servo_2': -math.pi / 2},
    {'battery_v': 0.0}, {'battery_v': 8.4},
    {'status': int(sum(Status)) & ~int(Status.RESTING), 'gait_id': 1},
    {'status': int(Status.GAIT_MODE | Status.RESTING), 'gait_id': 65535},
])
def test_the_edges_of_what_is_possible_pass(change):
    assert telemetry_problem(dataclasses.replace(AT_REST, **change)) is None


def test_every_limit_is_an_ordered_range_with_a_reason():
    assert all(limit.low < limit.high and limit.why for limit in LIMITS.values())


@pytest.mark.parametrize('change', [
    {'roll': math.pi, 'yaw': -math.pi}, {'pitch': math.pi / 2},
    {'servo_1': math.pi / 2 + 0.1, 'servo_2': -math.pi / 2 - 0.1},
    {'gyro': (34.9, -34.9, 0.0)}, {'battery_v': 9.0},
])
def test_compact_telemetry_rounded_at_the_edges_passes(change):
    compact = TelemetryCompact.from_telemetry(dataclasses.replace(AT_REST, **change))
    assert telemetry_problem(compact) is None


@pytest.mark.parametrize('change, field', [
    ({'roll': 31420}, 'roll'), ({'pitch': -15710}, 'pitch'), ({'servo_2': 16720}, 'servo_2'),
    ({'battery_mv': 9001}, 'battery_v'), ({'status': 0x0040}, 'outside gait mode'),
])
def test_impossible_compact_telemetry_is_named(change, field):
    compact = dataclasses.replace(TelemetryCompact.from_telemetry(AT_REST), **change)
    problem = telemetry_problem(compact)
    assert problem is not None and field in problem
