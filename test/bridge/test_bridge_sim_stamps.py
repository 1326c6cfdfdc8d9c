# SPDX-License-Identifier: Apache-2.0
"""
On simulated time the bridge waits for the graph's clock: no telemetry, no SERVO_CMD before it.

Until the bridge has heard the clock its timers do not run, its heartbeat among them, so the
fish holds neutral on its heartbeat failsafe; a command relayed meanwhile would step fish_sim's
lockstep clock with a command the fish ignores, and a sample would be stamped 0.
"""

import dataclasses
import time

import pytest
from wirefish_bridge.protocol import ServoCommand, Telemetry

# In-process and brief, it mostly waits: no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

FRAME = Telemetry(board_time_ms=0, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                  accel=(0.0, 0.0, 9.8), servo_1=0.0, servo_2=0.0, battery_v=8.0, status=0)
CLOCK_NS = 1_000 * 1_000_000_000  # the graph's clock once it starts
BEFORE_CLOCK_S = 3.0  # of a fish that booted, and a CPG that streams, before the clock
COMMAND = [0.3, -0.2]


def test_before_the_clock_nothing_is_published_or_relayed_then_all_is_on_it(
        fake_device, start_bridge, probe):
    from clock_owner import stamp
    from rosgraph_msgs.msg import Clock
    from wirefish_common.qos import CLOCK

    clock = probe.node.create_publisher(Clock, '/clock', CLOCK)
    start_bridge(fake_device.link, 'use_sim_time:=true')
    board_ms = 0

    def talk(seconds: float, with_clock: bool) -> list:
        """Play the fish (and the clock) for ``seconds``; return what the bridge sent it."""
        nonlocal board_ms
        sent = []
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if with_clock:
                clock.publish(Clock(clock=stamp(CLOCK_NS)))
            fake_device.send_fish_heartbeat()
            fake_device.send(dataclasses.replace(FRAME, board_time_ms=board_ms))
            board_ms += 10
            probe.spin_for(0.05, command=COMMAND)
            sent += fake_device.messages()
        return sent

    before = talk(BEFORE_CLOCK_S, with_clock=False)
    imu_before = len(probe.imu)
    after = talk(3.0, with_clock=True)
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in probe.imu]
    commands = [m for m in before if isinstance(m, ServoCommand)]
    commands_after = [m for m in after if isinstance(m, ServoCommand)]
    print(f'before the clock: {imu_before} imu/data, {len(commands)} SERVO_CMD; after: '
          f'{len(stamps) - imu_before} imu/data stamped {sorted(set(stamps[imu_before:]))}, '
          f'{len(commands_after)} SERVO_CMD')
    assert imu_before == 0 and not commands
    assert len(stamps) - imu_before >= 20 and set(stamps) == {CLOCK_NS}
    assert commands_after
