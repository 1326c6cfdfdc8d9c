"""fish_sim's firmware over its pty, driven by this test with pyserial (no bridge, no ROS)."""

from pathlib import Path
import time

from ament_index_python.packages import get_package_prefix
import pytest
import serial
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Status, Telemetry

BIN = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim'


def _telemetry_for(port, decoder, seconds, send=()):
    """Read telemetry for ``seconds`` while writing ``send`` frames every 20 ms."""
    out = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for frame in send:
            port.write(frame())
        out += [(time.monotonic(), f.message) for f in decoder.feed(port.read(4096))
                if isinstance(f.message, Telemetry)]
    return out


def test_firmware_goes_neutral_when_commands_or_heartbeats_stop(spawn, tmp_path):
    link = tmp_path / 'tty'
    spawn([str(BIN / 'fish_sim'), '--link', str(link), '--command-timeout', '0.3',
           '--heartbeat-timeout', '0.6'])
    deadline = time.monotonic() + 10.0
    while not link.is_symlink() and time.monotonic() < deadline:
        time.sleep(0.02)
    encoder, decoder = FrameEncoder(), StreamDecoder()
    with serial.Serial(str(link), 115200, timeout=0.02) as port:
        def command():
            return encoder.encode(ServoCommand(0.4, -0.3))

        def heartbeat():
            return encoder.encode(Heartbeat())
        driven = _telemetry_for(port, decoder, 1.0, (command, heartbeat))
        assert [driven[-1][1].servo_1, driven[-1][1].servo_2] == pytest.approx(
            [0.4, -0.3], abs=1e-3)
        assert driven[-1][1].status & Status.FAILSAFE_COMMAND == 0
        stopped = time.monotonic()
        no_commands = _telemetry_for(port, decoder, 1.0, (heartbeat,))
        first = next(t for t, m in no_commands if m.status & Status.FAILSAFE_COMMAND)
        neutral = next(t for t, m in no_commands if abs(m.servo_1) + abs(m.servo_2) < 1e-3)
        assert first - stopped < 0.3 + 0.15
        assert neutral - stopped < 0.3 + 0.25
        assert no_commands[-1][1].status & Status.FAILSAFE_HEARTBEAT == 0
        silent = _telemetry_for(port, decoder, 1.2)
        assert silent[-1][1].status & Status.FAILSAFE_HEARTBEAT
