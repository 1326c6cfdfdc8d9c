# SPDX-License-Identifier: Apache-2.0
"""The radio relay process: bytes cross it both ways, late by their air time, and a cut cuts."""

from collections.abc import Iterator
import json
import os
from pathlib import Path
import subprocess
import sys
import time

import pytest
from ros_utils import stop_process
from wirefish_sim.pty_device import PtyDevice
from wirefish_sim.radio_model import PRESETS


def _open_raw(path: Path) -> int:
    import tty
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    return fd


def _read_for(fd: int, seconds: float, want: int | None = None) -> tuple[bytes, float | None]:
    """Return what ``fd`` gives within ``seconds`` and when its ``want``-th byte came."""
    got = b''
    complete = None
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            got += os.read(fd, 4096)
        except BlockingIOError:
            time.sleep(0.0005)
            continue
        if want is not None and complete is None and len(got) >= want:
            complete = time.monotonic()
            break
    return got, complete


class Relay:
    """A radio_relay process between a pty of the test (the 'fish') and its own link."""

    def __init__(self, tmp_path: Path, preset: str, *flags: str) -> None:
        self.fish = PtyDevice(tmp_path / 'fish-tty')
        self.fish.open_pair()
        self.link = tmp_path / 'bridge-tty'
        self.stats = tmp_path / 'radio.json'
        self.proc = subprocess.Popen(
            [sys.executable, '-m', 'wirefish_sim.radio_relay', '--preset', preset,
             '--device', str(self.fish.link), '--link', str(self.link),
             '--stats', str(self.stats), '--stats-every', '0.2', *flags],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
        assert self.proc.stdout is not None
        self.proc.stdout.readline()   # the device line: the link is in place
        self.bridge = _open_raw(self.link)
        time.sleep(0.5)   # the relay opens the fish's device within REOPEN_S

    def close(self) -> str:
        """Stop the relay (once), close both ends; return what the relay said on stderr."""
        if self.bridge >= 0:
            os.close(self.bridge)
            self.bridge = -1
            stop_process(self.proc)
            self.fish.close()
            assert self.proc.stderr is not None
            self.said = self.proc.stderr.read()
        return self.said


@pytest.fixture
def relay_factory(tmp_path: Path) -> Iterator:
    made: list[Relay] = []

    def make(preset: str, *flags: str) -> Relay:
        made.append(Relay(tmp_path, preset, *flags))
        return made[-1]
    yield make
    for relay in made:
        relay.close()


def test_bytes_cross_both_ways_intact_on_the_wired_preset(relay_factory):
    relay = relay_factory('wired')
    os.write(relay.bridge, b'to the fish')
    got, _ = _read_for(relay.fish.fileno(), 1.0, want=11)
    assert got == b'to the fish'
    relay.fish.write(b'to the host')
    got, _ = _read_for(relay.bridge, 1.0, want=11)
    assert got == b'to the host'


def test_a_burst_takes_its_air_time_on_rf433(relay_factory):
    relay = relay_factory('rf433')
    params = PRESETS['rf433']
    sent = time.monotonic()
    os.write(relay.bridge, bytes(240))   # four full packets, one after the other
    got, complete = _read_for(relay.fish.fileno(), 3.0, want=240)
    assert complete is not None and got == bytes(240)
    # eq. R1: four packets of 60 bytes, 9 of overhead each: 0.23 s, then the latency.
    floor = 4 * params.air_time_s(60) + params.latency_s
    assert complete - sent >= floor
    print(f'rf433: 240 bytes in {complete - sent:.3f} s (air time and latency {floor:.3f} s)')


def test_a_cut_asked_for_loses_everything_for_its_length(relay_factory, tmp_path):
    control = tmp_path / 'radio-control'
    relay = relay_factory('wired', '--control', str(control))
    control.write_text('cut 0.5\n')
    deadline = time.monotonic() + 5.0   # the relay looks at every turn of its loop
    while control.exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not control.exists()   # read and removed
    os.write(relay.bridge, b'lost')
    got, _ = _read_for(relay.fish.fileno(), 0.2)
    assert got == b''
    time.sleep(0.3)
    os.write(relay.bridge, b'back')
    got, _ = _read_for(relay.fish.fileno(), 1.0, want=4)
    assert got == b'back'
    stderr = relay.close()
    assert 'radio_relay: cut ' in stderr
    document = json.loads(relay.stats.read_text())
    assert document['to_fish']['packets_cut'] >= 1
    assert len(document['cuts']) == 1


def test_the_stats_file_gives_the_link_use(relay_factory):
    relay = relay_factory('rf433')
    for _ in range(10):
        os.write(relay.bridge, bytes(60))
        time.sleep(0.1)
    time.sleep(0.5)
    document = json.loads(relay.stats.read_text())
    assert document['preset'] == 'rf433'
    assert document['to_fish']['bytes_offered'] == 600
    assert 0.0 < document['use_to_fish'] < 1.0
    assert document['use_to_host'] == 0.0


def test_bad_flags_are_refused_before_anything_opens(tmp_path):
    result = subprocess.run(
        [sys.executable, '-m', 'wirefish_sim.radio_relay', '--preset', 'rf433', '--device',
         str(tmp_path / 'a'), '--link', str(tmp_path / 'b'), '--cut', 'soon'],
        capture_output=True, text=True, timeout=30)
    assert result.returncode == 2
    assert 'AT:FOR' in result.stderr
    assert not (tmp_path / 'b').exists()
