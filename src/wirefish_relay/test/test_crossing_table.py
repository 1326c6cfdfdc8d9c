# SPDX-License-Identifier: Apache-2.0
"""The crossing table of the fish-shore radio link and the relay's hold, pure."""

from pathlib import Path

import pytest
from wirefish_relay.crossing import (crossing_table, default_crossing_file, LatestHold,
                                     load_crossing)

CONFIG = Path(__file__).resolve().parents[1] / 'config' / 'crossing.yaml'


def test_the_shipped_crossing_table_relays_the_fast_streams_slowly():
    table = {row.topic: row for row in load_crossing(CONFIG)}
    assert table['imu/data'].shore_topic == 'shore/imu/data'
    assert 0 < table['imu/data'].rate_hz <= 20 and 0 < table['servo_state'].rate_hz <= 20
    assert 'servo_cmd' not in table and 'body_wave' not in table


def test_the_installed_crossing_table_is_the_shipped_one():
    assert load_crossing(default_crossing_file()) == load_crossing(CONFIG)


@pytest.mark.parametrize('row, reason', [
    ({'topic': '/abs', 'type': 'a/msg/B', 'rate_hz': 1, 'qos': 'sensor'}, 'relative'),
    ({'topic': 'x', 'type': 'Imu', 'rate_hz': 1, 'qos': 'sensor'}, 'type'),
    ({'topic': 'x', 'type': 'a/msg/B', 'rate_hz': -1, 'qos': 'sensor'}, 'rate_hz'),
    ({'topic': 'x', 'type': 'a/msg/B', 'rate_hz': 1, 'qos': 'fast'}, 'qos'),
    ({'topic': 'x', 'type': 'a/msg/B', 'rate_hz': 1}, 'exactly'),
])
def test_a_bad_crossing_row_is_refused_with_the_reason(row, reason):
    with pytest.raises(ValueError, match=reason):
        crossing_table({'relayed': [row]})


def test_a_topic_relayed_twice_is_refused():
    row = {'topic': 'x', 'type': 'a/msg/B', 'rate_hz': 1, 'qos': 'sensor'}
    with pytest.raises(ValueError, match='twice'):
        crossing_table({'relayed': [row, row]})


def test_a_hold_sends_the_newest_message_once():
    hold = LatestHold()
    hold.put(b'1')
    hold.put(b'2')
    assert hold.take() == b'2'
    assert hold.take() is None
