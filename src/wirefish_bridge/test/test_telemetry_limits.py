"""The telemetry limits table: each field judged against its physical range."""

import dataclasses
import math

import numpy as np
import pytest
from wirefish_bridge.protocol import Status, Telemetry
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
    ({'battery_v': 12.6}, 'battery_v'), ({'status': 0x0040}, 'undefined bits'),
])
def test_each_impossible_field_is_named(change, field):
    problem = telemetry_problem(dataclasses.replace(AT_REST, **change))
    assert problem is not None and field in problem


@pytest.mark.parametrize('change', [
    {'roll': float(np.float32(math.pi))}, {'yaw': float(np.float32(-math.pi))},
    {'pitch': float(np.float32(math.pi / 2))}, {'gyro': (34.9, -34.9, 0.0)},
    {'accel': (0.0, 0.0, 156.0)}, {'servo_1': math.pi / 2, 'servo_2': -math.pi / 2},
    {'battery_v': 0.0}, {'battery_v': 8.4}, {'status': int(sum(Status))},
])
def test_the_edges_of_what_is_possible_pass(change):
    assert telemetry_problem(dataclasses.replace(AT_REST, **change)) is None


def test_every_limit_is_an_ordered_range_with_a_reason():
    assert all(limit.low < limit.high and limit.why for limit in LIMITS.values())
