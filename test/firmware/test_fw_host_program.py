# SPDX-License-Identifier: Apache-2.0
"""wirefish-fw-host is a virtual board on a real pty: identification, hello, commands, SIGINT."""

import subprocess
import time

from firmware_host import BUILD
import pytest
from ros_utils import stop_process
import serial
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Heartbeat, PROTOCOL_VERSION, Role, ServoCommand, Status,
                                      Telemetry)

PROGRAM = BUILD / 'host' / 'wirefish-fw-host'


@pytest.fixture
def board_pty(firmware_build: None):
    """Start wirefish-fw-host on a pty; yield the pty's path; stop it (SIGINT) afterwards."""
    proc = subprocess.Popen([str(PROGRAM), '--pty'], stdout=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert line.startswith('pty: '), line
        yield line.split(' ', 1)[1].strip()
    finally:
        assert stop_process(proc) == 0


def read_until(port: serial.Serial, decoder: StreamDecoder, done, timeout_s: float = 5.0):
    """Read frames until ``done(messages)`` is true; return the messages read."""
    messages = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        messages += [f.message for f in decoder.feed(port.read(port.in_waiting or 1))]
        if done(messages):
            return messages
    raise AssertionError(f'not seen within {timeout_s} s: {messages[-5:]}')


def test_program_identifies_itself_and_applies_commands_on_its_pty(board_pty: str):
    with serial.Serial(board_pty, 115200, timeout=0.05) as port:
        decoder, encoder = StreamDecoder(), FrameEncoder()
        read_until(port, decoder, lambda ms: any(
            isinstance(m, Heartbeat) and m.role == Role.FISH for m in ms))
        port.write(encoder.encode(Heartbeat(PROTOCOL_VERSION, Role.HOST, 0)) +
                   encoder.encode(ServoCommand(0.25, -3.0)))
        messages = read_until(port, decoder, lambda ms: any(
            isinstance(m, Telemetry) and m.servo_1 == 0.25 for m in ms))
        telemetry = [m for m in messages if isinstance(m, Telemetry)][-1]
        assert telemetry.servo_2 == pytest.approx(-1.5707963, abs=1e-6)
        # Synthetic IMU (no sensor on a host) and the clamp say so; the link is up.
        assert telemetry.status == Status.IMU_FAULT | Status.SERVO_CLAMPED
        assert telemetry.accel == pytest.approx((0.0, 0.0, 9.80665))
