# SPDX-License-Identifier: Apache-2.0
"""battery is decimated on the board's clock: frames that arrive in bursts keep its rate."""

import dataclasses
import time

import pytest
from wirefish_bridge.protocol import Telemetry

# In-process and brief, it mostly waits: no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

FRAME = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                  accel=(0.0, 0.0, 9.8), servo_1=0.0, servo_2=0.0, battery_v=8.0, status=0)
PERIOD_MS = 10  # the telemetry period of the board's clock
BATTERY_EVERY = 10  # frames per battery: the bridge's default battery_rate_hz, 10
BURSTS, BURST = 10, 30  # each burst 0.3 s of board time in one write
VOLT_STEP = 0.001  # frame i carries 8 V + i mV: a battery message names the frame it came from
LAST_BATTERY_WAIT_S = 30.0


def test_bursts_of_telemetry_give_one_battery_per_period_of_board_time(
        fake_device, start_bridge, probe):
    start_bridge(fake_device.link)
    deadline = time.monotonic() + 20.0
    while not probe.attitude:   # identify as a fish until telemetry is published
        assert time.monotonic() < deadline, 'no telemetry published'
        fake_device.send_fish_heartbeat()
        fake_device.send(FRAME)
        probe.spin_for(0.05)
    probe.spin_for(0.3)
    probe.battery.clear()
    # Three seconds of the board's telemetry in ten writes (a radio's bursts, or the frames of
    # a clock that outruns the bridge): each write's frames reach the bridge within
    # milliseconds, while its node clock barely moves.
    start_ms = 10_000
    for burst in range(BURSTS):
        frames = [dataclasses.replace(FRAME, board_time_ms=start_ms + i * PERIOD_MS,
                                      battery_v=8.0 + i * VOLT_STEP)
                  for i in range(burst * BURST, (burst + 1) * BURST)]
        fake_device.send(*frames)
        probe.spin_for(0.05)
    due = list(range(0, BURSTS * BURST, BATTERY_EVERY))
    # Until the last due battery is heard: a bridge the loaded machine starves takes the
    # bursts later (one run heard 6 of 30 a second after the last write), and changes nothing.
    # A lost last message ends the wait at the bound.
    deadline = time.monotonic() + LAST_BATTERY_WAIT_S
    while time.monotonic() < deadline and not any(
            round((m.voltage - 8.0) / VOLT_STEP) == due[-1] for m in probe.battery):
        probe.spin_for(0.05)
    probe.spin_for(0.2)  # one extra would come now
    published = sorted(round((m.voltage - 8.0) / VOLT_STEP) for m in probe.battery)
    print(f'{BURSTS * BURST} frames over {BURSTS * BURST * PERIOD_MS} ms of board time in '
          f'{BURSTS} writes: battery from frames {published} ({len(due)} due)')
    # Best effort, but local: a message may be lost on the way; none is extra or off schedule.
    assert set(published) <= set(due)
    assert len(published) >= 0.9 * len(due)
