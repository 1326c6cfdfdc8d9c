# SPDX-License-Identifier: Apache-2.0
"""On simulated time the bridge stamps telemetry on the graph's clock, none before it starts."""

import dataclasses
import time

import pytest
from wirefish_bridge.protocol import Telemetry

# In-process and brief, it mostly waits: no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

FRAME = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                  accel=(0.0, 0.0, 9.8), servo_1=0.0, servo_2=0.0, battery_v=8.0, status=0)
CLOCK_NS = 1_000 * 1_000_000_000  # the graph's clock once it starts
BEFORE_CLOCK_S = 3.0  # of frames from a fish that booted before the clock's first step


def test_no_telemetry_is_published_before_the_clock_and_all_after_is_on_it(
        fake_device, start_bridge, probe):
    from clock_owner import stamp
    from rosgraph_msgs.msg import Clock
    from wirefish_common.qos import CLOCK

    clock = probe.node.create_publisher(Clock, '/clock', CLOCK)
    start_bridge(fake_device.link, 'use_sim_time:=true')
    deadline = time.monotonic() + BEFORE_CLOCK_S
    board_ms = 0
    while time.monotonic() < deadline:  # a fish that talks before the clock starts
        fake_device.send_fish_heartbeat()
        fake_device.send(dataclasses.replace(FRAME, board_time_ms=board_ms))
        board_ms += 10
        probe.spin_for(0.05)
    before = len(probe.imu)
    deadline = time.monotonic() + 10.0
    while len(probe.imu) < before + 20:
        assert time.monotonic() < deadline, 'no imu/data once the clock started'
        clock.publish(Clock(clock=stamp(CLOCK_NS)))
        fake_device.send_fish_heartbeat()
        fake_device.send(dataclasses.replace(FRAME, board_time_ms=board_ms))
        board_ms += 10
        probe.spin_for(0.05)
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in probe.imu]
    print(f'{before} imu/data before the clock started, {len(stamps) - before} after; '
          f'stamps {sorted(set(stamps))}')
    assert before == 0
    assert set(stamps) == {CLOCK_NS}
