# SPDX-License-Identifier: Apache-2.0
"""
`wirefish up --radio PRESET` and the bridge's drive mode on each road (pure: no ROS).

``--radio`` puts the radio model (``wirefish_sim.radio_relay``) between the bridge and the fish:
the fish's process (the virtual fish, or the emulated board) publishes its device at
``<port>-fish``, the relay opens it and publishes its own pty at the bridge's ``<port>``, so the
bridge talks through the radio without knowing it. The radio runs on the wall clock, so the
virtual fish behind it does too (no --speed).

The drive mode of each road (``--drive-mode`` overrides it):

- ``--sim``: stream. The virtual fish's pty is a wire at full rate; stream mode keeps the
  host's servo_cmd the one command of the fish (the simulated-time road steps on it).
- ``--fish qemu``: stream. QEMU's pty is a wire too; the emulated board's stream path is what
  the firmware-in-the-loop tests check against the host's commands.
- ``--port``: gait. A real fish's port is, in the paper's build, the board's radio (RF200 or
  Bluetooth); gait mode fits a radio and works over a wire as well, stream mode needs a wire
  (or a computer on the fish wired to the board: choose ``--drive-mode stream`` there).
- ``--radio PRESET``: each preset's own (``RADIO_BRIDGE``): ``wired`` stream, ``bluetooth`` and
  ``rf433`` gait, with the telemetry their rate carries.

The launcher runs on the shore too, which has neither the bridge nor the virtual fish: the
preset and mode names are written here, and a test holds them equal to theirs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
import enum
from pathlib import Path

from wirefish_bringup.graph import NodeSpec, RestartPolicy


class Radio(enum.StrEnum):
    """The presets of ``--radio`` (wirefish_sim.radio_model.PRESETS)."""

    WIRED = 'wired'
    BLUETOOTH = 'bluetooth'
    RF433 = 'rf433'


class DriveMode(enum.StrEnum):
    """bridge_node's ``drive_mode`` (wirefish_bridge.bridge_node_parameters.DriveMode)."""

    STREAM = 'stream'
    GAIT = 'gait'


# What the bridge is told on each preset. rf433 (a 9600-baud UART into a half-duplex radio:
# 960 B/s): TELEMETRY_COMPACT at 10 Hz, host heartbeats at 2 Hz and HEALTH every 5 s, 8 % of
# the UART to the fish, 47 % from it, 36 % of the air together (PROTOCOL.md's bandwidth table).
# bluetooth (115200 baud): full telemetry at 50 Hz (0.27 of the UART), the gait on the board so
# that a burst at the surface steps nothing.
RADIO_BRIDGE: dict[Radio, Mapping[str, object]] = {
    Radio.WIRED: {'drive_mode': DriveMode.STREAM.value},
    Radio.BLUETOOTH: {'drive_mode': DriveMode.GAIT.value, 'telemetry_period_s': 0.02},
    Radio.RF433: {'drive_mode': DriveMode.GAIT.value, 'telemetry_period_s': 0.1,
                  'telemetry_form': 'compact', 'heartbeat_rate_hz': 2.0,
                  'health_period_s': 5.0},
}
RELAY_NAME = 'radio_relay'
FISH_LINK_SUFFIX = '-fish'


def road_drive_mode(*, port: bool, radio: Radio | None) -> DriveMode:
    """Return the drive mode of a road (see the module docstring)."""
    if radio is not None:
        return DriveMode(str(RADIO_BRIDGE[radio]['drive_mode']))
    return DriveMode.GAIT if port else DriveMode.STREAM


def bridge_settings(*, port: bool, radio: Radio | None,
                    drive_mode: DriveMode | None) -> dict[str, object]:
    """Return the bridge's parameters of the road: the preset's, the drive mode on top."""
    settings = dict(RADIO_BRIDGE[radio]) if radio is not None else {}
    settings['drive_mode'] = (drive_mode or road_drive_mode(port=port, radio=radio)).value
    return settings


def with_radio(specs: list[NodeSpec], radio: Radio, *, seed: int = 0,
               stats: Path | None = None, control: Path | None = None,
               tap: Path | None = None) -> list[NodeSpec]:
    """
    Return ``specs`` with the radio relay between the fish's process and the bridge.

    The process that creates the bridge's device link (the virtual fish or the emulated
    board) creates ``<link>-fish`` instead; the relay, started right after it, opens that
    and creates the bridge's link. ``stats``/``control``/``tap``: the relay's options.
    Raises ValueError when no process of ``specs`` creates a link (a real fish's port).
    """
    fish = [k for k, spec in enumerate(specs) if spec.links]
    if len(fish) != 1 or len(specs[fish[0]].links) != 1:
        raise ValueError('--radio goes between the bridge and one virtual fish or emulated '
                         'board (--sim or --fish qemu); a real fish has its own radio')
    index = fish[0]
    spec = specs[index]
    link = spec.links[0]
    behind = link.with_name(link.name + FISH_LINK_SUFFIX)
    moved = replace(spec, arguments=tuple(str(behind) if a == str(link) else a
                                          for a in spec.arguments),
                    links=(behind,))
    arguments = ['--preset', radio.value, '--device', str(behind), '--link', str(link),
                 '--seed', str(seed)]
    if stats is not None:
        arguments += ['--stats', str(stats)]
    if control is not None:
        arguments += ['--control', str(control)]
    if tap is not None:
        arguments += ['--tap', str(tap)]
    relay = NodeSpec('wirefish_sim', RELAY_NAME, RELAY_NAME, arguments=tuple(arguments),
                     restart=RestartPolicy(required=True), links=(link,))
    return [*specs[:index], moved, relay, *specs[index + 1:]]
