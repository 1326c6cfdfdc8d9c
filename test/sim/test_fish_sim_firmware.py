# SPDX-License-Identifier: Apache-2.0
"""fish_sim's firmware over its pty, driven by this test with pyserial (no bridge, no ROS)."""

from pathlib import Path
import time

from ament_index_python.packages import get_package_prefix
import pytest
import serial
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Ack, Gait, Heartbeat, LinkConfig, MsgType, ServoCommand,
                                      Status, Telemetry, telemetry_of, TelemetryCompact,
                                      TelemetryForm)

BIN = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim'


def _read_for(port, decoder, seconds, send=()):
    """Read frames for ``seconds`` while writing ``send`` frames every 20 ms."""
    out = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for frame in send:
            port.write(frame())
        out += [(time.monotonic(), f.message) for f in decoder.feed(port.read(4096))]
    return out


def _telemetry(frames):
    return [(t, telemetry_of(m)) for t, m in frames if telemetry_of(m) is not None]


def _open(spawn, tmp_path, *flags):
    link = tmp_path / 'tty'
    spawn([str(BIN / 'fish_sim'), '--link', str(link), *flags])
    deadline = time.monotonic() + 10.0
    while not link.is_symlink() and time.monotonic() < deadline:
        time.sleep(0.02)
    return serial.Serial(str(link), 115200, timeout=0.02)


def test_firmware_slews_to_neutral_when_commands_or_heartbeats_stop(spawn, tmp_path):
    encoder, decoder = FrameEncoder(), StreamDecoder()
    with _open(spawn, tmp_path, '--command-timeout', '0.3', '--heartbeat-timeout',
               '0.6') as port:
        def command():
            return encoder.encode(ServoCommand(0.4, -0.3))

        def heartbeat():
            return encoder.encode(Heartbeat())
        driven = _telemetry(_read_for(port, decoder, 1.0, (command, heartbeat)))
        assert [driven[-1][1].servo_1, driven[-1][1].servo_2] == pytest.approx(
            [0.4, -0.3], abs=1e-3)
        assert driven[-1][1].status & Status.FAILSAFE_COMMAND == 0
        stopped = time.monotonic()
        no_commands = _telemetry(_read_for(port, decoder, 1.0, (heartbeat,)))
        first = next(t for t, m in no_commands if m.status & Status.FAILSAFE_COMMAND)
        neutral = next(t for t, m in no_commands if abs(m.servo_1) + abs(m.servo_2) < 1e-3)
        assert first - stopped < 0.3 + 0.15
        # 0.4 rad at the failsafe's 2 rad/s: 0.2 s, a slew the servos follow (no step).
        assert 0.2 <= neutral - first < 0.2 + 0.25
        assert any(0.1 < m.servo_1 < 0.3 for t, m in no_commands if first <= t < neutral)
        assert no_commands[-1][1].status & Status.FAILSAFE_HEARTBEAT == 0
        silent = _telemetry(_read_for(port, decoder, 1.2))
        assert silent[-1][1].status & Status.FAILSAFE_HEARTBEAT


def test_gait_mode_over_the_pty_acks_swims_coasts_rests_and_resumes(spawn, tmp_path):
    encoder, decoder = FrameEncoder(), StreamDecoder()
    with _open(spawn, tmp_path, '--link-timeout', '0.3', '--coast', '0.5') as port:
        def heartbeat():
            return encoder.encode(Heartbeat())
        _read_for(port, decoder, 0.2, (heartbeat,))
        config_seq = encoder.next_seq
        port.write(encoder.encode(LinkConfig(20, TelemetryForm.COMPACT, 1000, 300, 500)))
        gait_seq = encoder.next_seq
        port.write(encoder.encode(Gait(7, 2.0, 0.4, 0.4, 0.0, 0.0, -0.41, 0.64, 1.76, 1.06,
                                       20.0)))
        swimming = _read_for(port, decoder, 1.5, (heartbeat,))
        acks = [m for _, m in swimming if isinstance(m, Ack)]
        assert acks == [Ack(MsgType.LINK_CONFIG, config_seq, 0), Ack(MsgType.GAIT, gait_seq, 0)]
        assert not any(isinstance(m, Telemetry) for _, m in swimming[-20:])
        compact = [m for _, m in swimming if isinstance(m, TelemetryCompact)]
        assert compact[-1].gait_id == 7 and compact[-1].status & Status.GAIT_MODE
        assert max(abs(m.expanded().servo_1) for m in compact[-25:]) > 0.3  # swimming
        silent = _telemetry(_read_for(port, decoder, 2.0))   # the host falls silent
        flags = [m.status & (Status.COASTING | Status.RESTING) for _, m in silent]
        assert Status.COASTING in flags and flags[-1] == Status.RESTING
        assert max(abs(m.servo_1) for _, m in silent[-10:]) < 0.05     # come to rest
        back = _telemetry(_read_for(port, decoder, 1.5, (heartbeat,)))
        assert back[-1][1].status & (Status.COASTING | Status.RESTING) == 0
        assert max(abs(m.servo_1) for _, m in back[-25:]) > 0.3       # the gait again
