# SPDX-License-Identifier: Apache-2.0
"""The example frames of PROTOCOL.md (v2), produced and accepted byte for byte by the C core."""

from pathlib import Path
import re

from firmware_host import FirmwareHost, to_record
import pytest
from wirefish_bridge.codec import StreamDecoder
from wirefish_bridge.protocol import (Ack, CalibrationSource, ClockSource, ErrorCode,
                                      ErrorReport, Gait, Health, Heartbeat, LinkConfig, MsgType,
                                      ResetCause, Role, ServoCommand, ServoTrim,
                                      ServoTrimReport, Status, Telemetry, TelemetryCompact,
                                      TelemetryForm, TrimOp)

PROTOCOL = Path(__file__).resolve().parents[2] / 'src' / 'wirefish_bridge' / 'PROTOCOL.md'
STATUS = int(Status.LOW_BATTERY | Status.GAIT_MODE)

# The documented values of each example, in the order PROTOCOL.md prints them: (message, seq).
EXAMPLES = [
    (Heartbeat(2, Role.HOST, 5000), 0),
    (Heartbeat(2, Role.FISH, 1500), 9),
    (LinkConfig(50, TelemetryForm.COMPACT, 5000, 1500, 3000), 4),
    (ServoCommand(0.25, -0.5), 7),
    (Gait(3, 1.5, 0.375, 0.5, 0.0625, -0.0625, -0.41, 0.64, 1.76, 1.06, 20.0), 8),
    (Ack(MsgType.GAIT, 8, 0), 12),
    (Telemetry(1234, 0.1, -0.2, 3.0, (0.0, 0.5, -1.0), (0.25, 0.0, 9.75), 0.375, -0.5, 8.125,
               STATUS, 3), 0x0102),
    (TelemetryCompact(1234, 1000, -2000, 30000, (0, 500, -1000), (250, 0, 9750), 3750, -5000,
                      8125, STATUS, 3), 0x0103),
    (Health(ResetCause.FAULT, ClockSource.HSE_PLL, 0x0F, 0x08001234, 0xFFFFFFF9, 0x00000400,
            0x40000000, 123456, 612, 2048, 0, 0, 3, 1, 0, 0, 2, 1, 1, 1), 0x0104),
    (ErrorReport(ErrorCode.BAD_CRC, 42), 3),
    (ServoTrim(1, TrimOp.SAVE, -1, 1520.0, 600.0), 13),
    (ServoTrimReport(1, CalibrationSource.STORED, -1, 1520.0, 600.0, 500.0, 2500.0), 14),
]
NAMES = [type(message).__name__ + str(i) for i, (message, _) in enumerate(EXAMPLES)]


def example_frames() -> list[bytes]:
    """Return the hex blocks of PROTOCOL.md's "Example frames" section, in order."""
    section = PROTOCOL.read_text().split('## Example frames', 1)[1].split('\n## ', 1)[0]
    blocks = re.findall(r'```\n(.*?)```', section, re.S)
    return [bytes.fromhex(block.replace('\n', ' ')) for block in blocks]


def test_protocol_md_prints_an_example_of_every_type():
    assert len(example_frames()) == len(EXAMPLES)
    assert {type(message).KIND for message, _ in EXAMPLES} == set(MsgType)


@pytest.mark.parametrize('index', range(len(EXAMPLES)), ids=NAMES)
def test_c_core_encodes_the_example_byte_for_byte(host_lib: FirmwareHost, index: int):
    message, seq = EXAMPLES[index]
    assert host_lib.encode_stream(to_record(message, seq)) == example_frames()[index]


@pytest.mark.parametrize('index', range(len(EXAMPLES)), ids=NAMES)
def test_c_core_decodes_the_example_to_its_values(host_lib: FirmwareHost, index: int):
    message, seq = EXAMPLES[index]
    frames, stats = host_lib.decode_stream(example_frames()[index])
    assert frames.tobytes() == to_record(message, seq).tobytes()
    assert stats['frames_ok'] == 1 and stats['resyncs'] == 0


def test_board_acts_on_the_host_examples(board: FirmwareHost):
    frames = example_frames()
    heartbeat, servo_cmd = frames[0], frames[3]
    board.step(1, heartbeat)
    board.step(2, servo_cmd)
    state = board.snapshot()
    assert state.host_seen and state.commands_applied == 1
    assert list(state.target) == [0.25, -0.5]
    # 1500 us + 636.62 us/rad x angle at 1 tick per us.
    assert [board.compare(0), board.compare(1)] == [1659, 1182]


def test_board_answers_the_gait_and_link_config_examples_with_acks(board: FirmwareHost):
    frames = example_frames()
    board.step(1, frames[0])
    out = board.step(2, frames[2])  # LINK_CONFIG seq 4
    assert Ack(MsgType.LINK_CONFIG, 4, 0) in [f.message for f in StreamDecoder().feed(out)]
    out = board.step(3, frames[4])  # GAIT seq 8
    assert Ack(MsgType.GAIT, 8, 0) in [f.message for f in StreamDecoder().feed(out)]
    gait = board.gait()
    assert (gait.gait_mode, gait.gait_id, gait.telemetry_form, gait.health_period_ms) == (
        1, 3, TelemetryForm.COMPACT, 5000)
