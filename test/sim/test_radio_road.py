# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --radio`: the relay between the fish and the bridge, the drive mode per road."""

from pathlib import Path

import pytest
from wirefish_bridge.bridge_node_parameters import DriveMode as BridgeMode, RULE, TABLE
from wirefish_bringup.graph import fish_graph
from wirefish_launcher.radio_road import (bridge_settings, DriveMode, Radio, RADIO_BRIDGE,
                                          RELAY_NAME, road_drive_mode, with_radio)
from wirefish_sim.radio_model import PRESETS


def test_the_launcher_names_what_the_relay_and_the_bridge_know():
    assert [radio.value for radio in Radio] == list(PRESETS)
    assert [mode.value for mode in DriveMode] == [mode.value for mode in BridgeMode]


@pytest.mark.parametrize('radio', list(Radio))
def test_each_preset_gives_the_bridge_values_it_accepts(radio):
    values = {spec.name: spec.default for spec in TABLE}
    values.update(bridge_settings(port=False, radio=radio, drive_mode=None))
    assert RULE(values) is None


def test_each_road_has_its_drive_mode():
    assert road_drive_mode(port=False, radio=None) is DriveMode.STREAM   # --sim, --fish qemu
    assert road_drive_mode(port=True, radio=None) is DriveMode.GAIT      # --port
    assert road_drive_mode(port=False, radio=Radio.RF433) is DriveMode.GAIT
    assert road_drive_mode(port=False, radio=Radio.BLUETOOTH) is DriveMode.GAIT
    assert road_drive_mode(port=False, radio=Radio.WIRED) is DriveMode.STREAM
    chosen = bridge_settings(port=False, radio=Radio.RF433, drive_mode=DriveMode.STREAM)
    assert chosen['drive_mode'] == 'stream' and chosen['telemetry_form'] == 'compact'


@pytest.mark.parametrize('road', ['sim', 'qemu'])
def test_the_relay_sits_between_the_fish_and_the_bridge(road):
    specs = fish_graph('/r', sim=road == 'sim', qemu=road == 'qemu')
    fish_before = next(spec for spec in specs if spec.links)
    port = fish_before.links[0]
    radio = with_radio(specs, Radio.RF433, stats=Path('/tmp/s.json'), control=Path('/tmp/c'))
    names = [spec.name for spec in radio]
    fish = radio[names.index(fish_before.name)]
    relay = radio[names.index(RELAY_NAME)]
    assert names.index(RELAY_NAME) == names.index(fish_before.name) + 1
    assert names.index(RELAY_NAME) < names.index('bridge_node')
    behind = Path(f'{port}-fish')
    assert fish.links == (behind,) and str(behind) in fish.arguments
    assert str(port) not in fish.arguments
    assert relay.links == (port,)
    arguments = list(relay.arguments)
    assert arguments[arguments.index('--device') + 1] == str(behind)
    assert arguments[arguments.index('--link') + 1] == str(port)
    assert arguments[arguments.index('--preset') + 1] == 'rf433'
    assert relay.restart.required
    bridge = radio[names.index('bridge_node')]
    assert bridge.parameters['port'] == str(port)   # the bridge is not told of the radio


def test_a_real_fish_takes_no_radio_model():
    with pytest.raises(ValueError, match='own radio'):
        with_radio(fish_graph('/r', sim=False, port='/dev/ttyUSB0'), Radio.RF433)


def test_the_narrow_preset_asks_for_compact_telemetry():
    assert RADIO_BRIDGE[Radio.RF433]['telemetry_form'] == 'compact'
