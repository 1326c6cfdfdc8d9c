# SPDX-License-Identifier: Apache-2.0
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
FISH_HEARTBEAT_HZ = 2.0
GAIT_CHANGES_HZ = 1.0  # each a GAIT and its ACK
# A row's first cell names its traffic: the drive mode, the telemetry and its period, and the
# host's heartbeat rate and the HEALTH period (the rows of wirefish_launcher.radio_road's
# RADIO_BRIDGE name that preset's settings; the bridge's defaults are 5 Hz and 2 s).
ROW = re.compile(r'(?P<mode>stream|gait): (?P<form>TELEMETRY|TELEMETRY_COMPACT) every '
                 r'(?P<period>\d+) ms, host HEARTBEAT (?P<heartbeat>[\d.]+) Hz, HEALTH every '
                 r'(?P<health>[\d.]+) s')


def frames(label: str) -> tuple[list, list]:
    """Return a row's (host -> fish, fish -> host) frames: (per second, bytes each)."""
    match = ROW.fullmatch(label)
    assert match, f'a row PROTOCOL.md names unlike {ROW.pattern}: {label!r}'
    telemetry = WIRE['telemetry' if match['form'] == 'TELEMETRY' else 'compact']
    to_fish = [(float(match['heartbeat']), WIRE['heartbeat'])]
    to_host = [(1000.0 / int(match['period']), telemetry),
               (FISH_HEARTBEAT_HZ, WIRE['heartbeat']),
               (1.0 / float(match['health']), WIRE['health'])]
    if match['mode'] == 'stream':
        to_fish.append((100.0, WIRE['servo_cmd']))
    else:
        to_fish.append((GAIT_CHANGES_HZ, WIRE['gait']))
        to_host.append((GAIT_CHANGES_HZ, WIRE['ack']))
    return to_fish, to_host


def rate(frames: list) -> float:
    """Return the bytes a second of ``frames``."""
    return sum(hz * size for hz, size in frames)


def air(radio: RadioParameters, frames: list) -> float:
    """Return the share of ``radio``'s air time the frames take, one packet per frame."""
    return sum(hz * radio.air_time_s(size) for hz, size in frames)


def expected_cells(label: str) -> list[str]:
    """Return the cells after a row's first: B/s each way, then each preset's share."""
    to_fish, to_host = frames(label)
    cells = [f'{rate(to_fish):,.0f}', f'{rate(to_host):,.0f}']
    for radio in PRESETS.values():
        load = (f'{100 * rate(to_fish) / radio.capacity_bytes_s:.0f} % / '
                f'{100 * rate(to_host) / radio.capacity_bytes_s:.0f} %')
        if radio.half_duplex:
            load += f'; air {100 * (air(radio, to_fish) + air(radio, to_host)):.0f} % (shared)'
        cells.append(load)
    return cells


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


def test_the_table_has_stream_mode_and_each_radio_presets_gait():
    labels = list(documented_rows())
    assert any(label.startswith('stream') for label in labels)
    # rf433's and bluetooth's settings (wirefish_launcher.radio_road.RADIO_BRIDGE).
    assert 'gait: TELEMETRY_COMPACT every 100 ms, host HEARTBEAT 2 Hz, HEALTH every 5 s' in labels
    assert 'gait: TELEMETRY every 20 ms, host HEARTBEAT 5 Hz, HEALTH every 2 s' in labels


@pytest.mark.parametrize('label', list(documented_rows()))
def test_each_row_is_recomputed_from_the_sizes_and_the_presets(label):
    assert documented_rows()[label] == expected_cells(label)


def test_the_presets_rates_are_the_documented_ones():
    assert {name: round(radio.capacity_bytes_s) for name, radio in PRESETS.items()} == {
        'wired': 11520, 'bluetooth': 11520, 'rf433': 960}
