"""PROTOCOL.md's bandwidth table, recomputed from the message sizes and the radio presets."""

from pathlib import Path
import re

import pytest
from wirefish_bridge.codec import encode_frame
from wirefish_bridge.protocol import (Ack, Gait, Health, Heartbeat, ServoCommand, Telemetry,
                                      TelemetryCompact)
from wirefish_sim.radio_model import PRESETS, RadioParameters

PROTOCOL = Path(__file__).resolve().parents[2] / 'wirefish_bridge' / 'PROTOCOL.md'
# The longest each frame can be on the wire: values that need no COBS code byte inside.
WIRE = {name: len(encode_frame(message, 0x0101)) for name, message in {
    'heartbeat': Heartbeat(), 'servo_cmd': ServoCommand(0.1, 0.1),
    'gait': Gait(1, 1.0, 0.1, 0.1), 'ack': Ack(0x11, 0x0101, 0),
    'telemetry': Telemetry(1, *[0.1] * 3, (0.1,) * 3, (0.1,) * 3, 0.1, 0.1, 8.0),
    'compact': TelemetryCompact(1, 1, 1, 1, (1,) * 3, (1,) * 3, 1, 1, 8000),
    'health': Health()}.items()}
FISH_BACKGROUND = [(2.0, WIRE['heartbeat']), (0.5, WIRE['health'])]   # per second, bytes


def modes() -> dict[str, tuple[list, list]]:
    """Return each table row's (host -> fish, fish -> host) frames: (per second, bytes)."""
    rows = {'stream: SERVO_CMD 100 Hz, TELEMETRY every 10 ms': (
        [(100.0, WIRE['servo_cmd']), (5.0, WIRE['heartbeat'])],
        [(100.0, WIRE['telemetry'])] + FISH_BACKGROUND)}
    for period_ms in (10, 50, 100, 200):
        rows[f'gait: GAIT on change, TELEMETRY_COMPACT every {period_ms} ms'] = (
            [(1.0, WIRE['gait']), (5.0, WIRE['heartbeat'])],
            [(1000.0 / period_ms, WIRE['compact']), (1.0, WIRE['ack'])] + FISH_BACKGROUND)
    return rows


def use(radio: RadioParameters, frames: list) -> float:
    """Return the share of ``radio``'s air time the frames take, one packet per frame."""
    return sum(rate * radio.air_time_s(size) for rate, size in frames)


def documented_rows() -> dict[str, list[str]]:
    """Return the bandwidth table of PROTOCOL.md: first cell -> the other cells."""
    section = PROTOCOL.read_text().split('## Bandwidth', 1)[1]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if line.startswith('|') and cells[0].startswith(('stream', 'gait')):
            rows[cells[0]] = cells[1:]
    return rows


def test_the_frame_sizes_are_the_documented_ones():
    assert WIRE == {'heartbeat': 14, 'servo_cmd': 16, 'gait': 50, 'ack': 12, 'telemetry': 64,
                    'compact': 40, 'health': 69}


def test_the_presets_are_the_documented_columns():
    header = next(line for line in PROTOCOL.read_text().split('## Bandwidth', 1)[1].splitlines()
                  if line.startswith('| drive mode'))
    assert re.findall(r'`(\w+)`', header) == list(PRESETS)


@pytest.mark.parametrize('mode', list(modes()))
def test_each_row_is_recomputed_from_the_sizes_and_the_presets(mode):
    to_fish, to_host = modes()[mode]
    expected = [f'{sum(r * b for r, b in to_fish):,.0f}', f'{sum(r * b for r, b in to_host):,.0f}']
    for radio in PRESETS.values():
        if radio.half_duplex:
            expected.append(f'{100 * (use(radio, to_fish) + use(radio, to_host)):.0f} % (shared)')
        else:
            expected.append(f'{100 * use(radio, to_fish):.0f} % / '
                            f'{100 * use(radio, to_host):.0f} %')
    assert documented_rows()[mode] == expected
