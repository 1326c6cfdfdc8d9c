# SPDX-License-Identifier: Apache-2.0
"""ROS messages of the bridge from either telemetry form, and of HEALTH."""

import math

from builtin_interfaces.msg import Time
import pytest
from wirefish_bridge.protocol import (ClockSource, Health, HealthFlags, ResetCause, Status,
                                      Telemetry, TelemetryCompact)
from wirefish_bridge.ros_messages import (attitude_message, battery_message, health_level,
                                          health_values, imu_message, servo_state_message)

STAMP = Time(sec=12, nanosec=5)
FULL = Telemetry(board_time_ms=99, roll=0.123456, pitch=-0.654321, yaw=3.1,
                 gyro=(0.01, -2.5, 30.0), accel=(0.3, -0.02, 9.81), servo_1=1.2345678,
                 servo_2=-0.4, battery_v=7.4321,
                 status=int(Status.IMU_FAULT | Status.GAIT_MODE), gait_id=9)
COMPACT = TelemetryCompact.from_telemetry(FULL)


def _imu(telemetry):
    return imu_message(telemetry, STAMP, 'imu_link', (0.01, 0.01, 0.1), 0.005, 0.05)


def test_a_compact_frame_gives_the_same_imu_message_to_its_precision():
    full, compact = _imu(FULL), _imu(COMPACT)
    assert compact.header == full.header
    for part in ('orientation', 'angular_velocity', 'linear_acceleration'):
        a, b = getattr(full, part), getattr(compact, part)
        for axis in ('x', 'y', 'z'):
            assert getattr(b, axis) == pytest.approx(getattr(a, axis), abs=5e-4)
    assert list(compact.orientation_covariance) == list(full.orientation_covariance)
    assert compact.orientation_covariance[0] == -1.0  # IMU_FAULT survives the compact form


def test_a_compact_frame_gives_the_same_attitude_servo_and_battery_messages():
    a, b = attitude_message(FULL, STAMP, 'imu_link'), attitude_message(COMPACT, STAMP, 'imu_link')
    assert (b.vector.x, b.vector.y, b.vector.z) == pytest.approx(
        (a.vector.x, a.vector.y, a.vector.z), abs=0.5e-4)
    full_servo = servo_state_message(FULL, STAMP)
    compact_servo = servo_state_message(COMPACT, STAMP)
    assert list(compact_servo.name) == list(full_servo.name)
    assert list(compact_servo.position) == pytest.approx(list(full_servo.position), abs=0.5e-4)
    full_battery = battery_message(FULL, STAMP, True)
    compact_battery = battery_message(COMPACT, STAMP, True)
    assert compact_battery.voltage == pytest.approx(full_battery.voltage, abs=0.5e-3)
    assert compact_battery.power_supply_health == full_battery.power_supply_health
    assert math.isnan(compact_battery.current)


def test_health_of_a_fault_reset_warns_with_the_pc():
    health = Health(ResetCause.FAULT, ClockSource.HSE_PLL,
                    int(HealthFlags.FAULT_RECORD | HealthFlags.STACK_GUARD), 0x08001234,
                    0xFFFFFFF9, 0x400, 0x40000000, 5000, 600, 2048, rx_crc=3)
    level, message = health_level(health)
    assert level == 1 and 'FAULT' in message and '0x08001234' in message
    values = health_values(health)
    assert values['reset_cause'] == 'FAULT' and values['fault_pc'] == '0x08001234'
    assert values['health_flags'] == 'FAULT_RECORD, STACK_GUARD'
    assert values['board_rx_crc'] == 3 and values['stack_free_min_bytes'] == '600 of 2048'


def test_the_virtual_fish_health_is_ok_and_unknown_values_are_shown_as_numbers():
    assert health_level(Health(ResetCause.POWER_ON, ClockSource.EMULATED))[0] == 0
    assert health_level(Health(ResetCause.PIN, ClockSource.HSI_PLL))[0] == 1
    values = health_values(Health(reset_cause=42, clock_source=7))
    assert values['reset_cause'] == 'unknown (42)' and values['clock_source'] == 'unknown (7)'
    assert 'fault_pc' not in values
