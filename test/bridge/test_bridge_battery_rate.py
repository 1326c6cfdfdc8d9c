# SPDX-License-Identifier: Apache-2.0
"""battery is decimated on the board's clock: frames that arrive in a burst keep its rate."""

import dataclasses
import time

import pytest
from wirefish_bridge.protocol import Telemetry

# In-process and brief, it mostly waits: no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

FRAME = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                  accel=(0.0, 0.0, 9.8), servo_1=0.0, servo_2=0.0, battery_v=8.0, status=0)
PERIOD_MS = 10  # the telemetry period of the board's clock
BATTERY_PERIOD_MS = 100  # the bridge's default battery_rate_hz, 10


def test_a_burst_of_telemetry_gives_one_battery_per_period_of_board_time(
        fake_device, start_bridge, probe):
    start_bridge(fake_device.link)
    deadline = time.monotonic() + 20.0
    while not probe.attitude:   # identify as a fish until telemetry is published
        assert time.monotonic() < deadline, 'no telemetry published'
        fake_device.send_fish_heartbeat()
        fake_device.send(FRAME)
        probe.spin_for(0.05)
    probe.spin_for(0.3)
    probe.attitude.clear()
    probe.battery.clear()
    # Three seconds of the board's telemetry in one write: a radio's burst, or frames of a
    # clock that outruns the bridge; they reach the bridge within milliseconds of each other.
    start_ms = 10_000
    burst = [dataclasses.replace(FRAME, board_time_ms=start_ms + i * PERIOD_MS, roll=0.001 * i)
             for i in range(300)]
    fake_device.send(*burst)
    deadline = time.monotonic() + 20.0
    while len(probe.attitude) < len(burst) and time.monotonic() < deadline:
        probe.spin_for(0.1)
    print(f'{len(burst)} frames over {len(burst) * PERIOD_MS} ms of board time: '
          f'{len(probe.attitude)} attitude, {len(probe.battery)} battery published')
    assert len(probe.attitude) == len(burst)
    assert len(probe.battery) == len(burst) * PERIOD_MS // BATTERY_PERIOD_MS
