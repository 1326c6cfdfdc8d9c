# SPDX-License-Identifier: Apache-2.0
"""Finite but impossible telemetry, forged on the pty, is counted and never published (12.9)."""

import dataclasses
import time

import pytest
from wirefish_bridge.protocol import Telemetry

# It mostly waits (0.19 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

VALID = Telemetry(board_time_ms=0, roll=0.0, pitch=0.1, yaw=-0.2, gyro=(0.0, 0.0, 0.3),
                  accel=(0.1, 0.0, 9.8), servo_1=0.2, servo_2=-0.1, battery_v=8.0, status=0)
# One impossible field each (first a roll of 3.4e38, near float32's largest), the rest valid.
FORGED = [
    {'roll': 3.4e38}, {'pitch': 2.0}, {'yaw': -4.0}, {'gyro': (0.0, 1.0e3, 0.0)},
    {'accel': (0.0, 0.0, 1.0e4)}, {'servo_1': 10.0}, {'servo_2': -3.0},
    {'battery_v': 1.0e6}, {'battery_v': -1.0}, {'status': 0x8000},
]


def test_impossible_telemetry_is_counted_and_dropped_and_valid_frames_pass(
        fake_device, start_bridge, probe):
    start_bridge(fake_device.link)
    deadline = time.monotonic() + 20.0
    while not probe.attitude:   # identify as a fish until valid telemetry is published
        assert time.monotonic() < deadline, 'no telemetry published'
        fake_device.send_fish_heartbeat()
        fake_device.send(VALID)
        probe.spin_for(0.05)
    probe.spin_for(0.3)
    probe.attitude.clear()
    probe.battery.clear()
    valid_rolls = []
    for i, forged in enumerate(FORGED):
        roll = 0.01 * (i + 1)
        valid_rolls.append(roll)
        fake_device.send(dataclasses.replace(VALID, board_time_ms=i, roll=roll),
                         dataclasses.replace(VALID, board_time_ms=i, **forged))
        probe.spin_for(0.05)
    fake_device.send_fish_heartbeat()
    probe.spin_for(1.5)
    values = probe.last_diagnostics()
    published = [m.vector.x for m in probe.attitude]
    print(f'published rolls {published}; batteries {[m.voltage for m in probe.battery]}; '
          f'rejected {values["telemetry_rejected"]}: {values["last_telemetry_rejected"]!r}')
    assert all(any(abs(p - r) < 1e-6 for r in valid_rolls) for p in published)
    assert all(m.voltage == pytest.approx(8.0) for m in probe.battery)
    assert all(abs(m.vector.y - 0.1) < 1e-6 for m in probe.attitude)
    assert len(published) >= len(FORGED) // 2   # best effort, but local: most arrive
    assert values['telemetry_rejected'] == str(len(FORGED))
    assert 'status' in values['last_telemetry_rejected']
