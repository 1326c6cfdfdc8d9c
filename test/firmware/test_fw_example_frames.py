"""The five example frames of PROTOCOL.md, produced and accepted byte for byte by the C core."""

from pathlib import Path
import re

from firmware_host import FirmwareHost, MSG_DTYPE
import numpy as np
import pytest

PROTOCOL = Path(__file__).resolve().parents[2] / 'src' / 'wirefish_bridge' / 'PROTOCOL.md'
LOW_BATTERY = 0x0008


def example_frames() -> list[bytes]:
    """Return the hex blocks of PROTOCOL.md's "Example frames" section, in order."""
    section = PROTOCOL.read_text().split('## Example frames', 1)[1].split('\n## ', 1)[0]
    blocks = re.findall(r'```\n(.*?)```', section, re.S)
    return [bytes.fromhex(block.replace('\n', ' ')) for block in blocks]


def message(**fields) -> np.ndarray:
    """Return one MSG_DTYPE record with ``fields`` (floats as a list in ``f``)."""
    record = np.zeros(1, MSG_DTYPE)
    for name, value in fields.items():
        if name == 'f':
            record['f'][0, :len(value)] = value
        else:
            record[name] = value
    return record


# The documented values of each example, in the order PROTOCOL.md prints them.
EXAMPLES = [
    message(type=0x01, seq=0, code=1, role=0, time=5000),
    message(type=0x01, seq=9, code=1, role=1, time=1500),
    message(type=0x10, seq=7, f=[0.25, -0.5]),
    message(type=0x20, seq=0x0102, time=1234, ref=LOW_BATTERY,
            f=[0.1, -0.2, 3.0, 0.0, 0.5, -1.0, 0.25, 0.0, 9.75, 0.375, -0.5, 8.125]),
    message(type=0x7F, seq=3, code=1, ref=42),
]
NAMES = ['host heartbeat', 'fish heartbeat', 'servo_cmd', 'telemetry', 'error']


def test_protocol_md_prints_five_example_frames():
    assert len(example_frames()) == len(EXAMPLES) == 5


@pytest.mark.parametrize('index', range(5), ids=NAMES)
def test_c_core_encodes_the_example_byte_for_byte(host_lib: FirmwareHost, index: int):
    assert host_lib.encode_stream(EXAMPLES[index]) == example_frames()[index]


@pytest.mark.parametrize('index', range(5), ids=NAMES)
def test_c_core_decodes_the_example_to_its_values(host_lib: FirmwareHost, index: int):
    frames, stats = host_lib.decode_stream(example_frames()[index])
    assert frames.tobytes() == EXAMPLES[index].tobytes()
    assert stats['frames_ok'] == 1 and stats['resyncs'] == 0


def test_board_acts_on_the_host_examples(board: FirmwareHost):
    heartbeat, _, servo_cmd, _, _ = example_frames()
    board.step(1, heartbeat)
    board.step(2, servo_cmd)
    state = board.snapshot()
    assert state.host_seen and state.commands_applied == 1
    assert list(state.target) == [0.25, -0.5]
    # 1500 us + 636.62 us/rad x angle at 1 tick per us.
    assert [board.compare(0), board.compare(1)] == [1659, 1182]
