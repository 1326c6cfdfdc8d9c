# SPDX-License-Identifier: Apache-2.0
"""The serial link opens its device exclusively and writes only to a peer that identified."""

import os
import threading
import time
import tty

import pytest
import serial
from wirefish_bridge.transport import LinkState, lock_holder, PeerNotIdentified, SerialLink


class SilentPort:
    """A pyserial stand-in that never sends a byte and records what is written to it."""

    in_waiting = 0

    def __init__(self, written: list[bytes]) -> None:
        self.written = written

    def reset_input_buffer(self) -> None:
        pass

    def read(self, size: int) -> bytes:
        time.sleep(0.001)
        return b''

    def write(self, data: bytes) -> int:
        self.written.append(data)
        return len(data)

    def close(self) -> None:
        pass


def _wait(predicate, timeout_s: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.002)
    return predicate()


@pytest.fixture
def pty_path():
    master, slave = os.openpty()
    tty.setraw(slave)
    yield os.ttyname(slave)
    os.close(master)
    os.close(slave)


def test_nothing_is_written_before_the_peer_identifies_itself():
    written, states = [], []
    link = SerialLink('/dev/fake', 115200, lambda chunk: None,
                      lambda state, detail: states.append(state), identify_timeout_s=30.0,
                      serial_factory=lambda *args, **kwargs: SilentPort(written))
    link.start()
    assert _wait(lambda: link.state is LinkState.IDENTIFYING)
    with pytest.raises(PeerNotIdentified):
        link.write(b'x')
    link.identify_peer()
    link.write(b'y')
    link.stop()
    assert written == [b'y'] and link.stats.writes_withheld == 1
    assert states[:3] == [LinkState.CONNECTING, LinkState.IDENTIFYING, LinkState.CONNECTED]


def test_a_peer_that_never_identifies_itself_is_closed_and_reopened():
    written, opens = [], []

    def factory(*args, **kwargs):
        opens.append(args[0])
        return SilentPort(written)
    link = SerialLink('/dev/fake', 115200, lambda chunk: None, identify_timeout_s=0.02,
                      backoff_min_s=0.001, backoff_max_s=0.002, serial_factory=factory)
    link.start()
    assert _wait(lambda: link.stats.identify_timeouts >= 3)
    link.stop()
    assert len(opens) >= 3 and written == []
    assert link.stats.last_open_unidentified and 'did not identify' in link.stats.last_error


def test_without_identification_the_link_writes_at_once(pty_path):
    link = SerialLink(pty_path, 115200, lambda chunk: None)
    link.start()
    assert _wait(lambda: link.connected)
    link.write(b'\x00')
    link.stop()


def test_a_second_link_on_the_same_device_cannot_open_it_and_says_who_holds_it(pty_path):
    first = SerialLink(pty_path, 115200, lambda chunk: None)
    first.start()
    assert _wait(lambda: first.connected)
    reports = []
    second = SerialLink(pty_path, 115200, lambda chunk: None,
                        lambda state, detail: reports.append(detail),
                        backoff_min_s=0.005, backoff_max_s=0.01)
    second.start()
    assert _wait(lambda: second.stats.open_failures >= 3)
    assert not second.connected
    assert any(f'in use by another process (pid {os.getpid()})' in r for r in reports)
    first.stop()
    assert _wait(lambda: second.connected)   # it kept retrying
    second.stop()


def test_a_held_lock_names_its_process(pty_path):
    with serial.Serial(pty_path, exclusive=True):
        assert lock_holder(pty_path) == os.getpid()
    assert lock_holder(pty_path) is None


class VanishingPort(SilentPort):
    """Fails like an unplugged device once ``vanish`` is set."""

    def __init__(self, written: list[bytes], vanish: threading.Event) -> None:
        super().__init__(written)
        self.vanish = vanish

    def read(self, size: int) -> bytes:
        if self.vanish.is_set():
            raise serial.SerialException('device disappeared')
        return super().read(size)


def test_identification_belongs_to_one_open_of_the_device():
    written, vanish = [], threading.Event()
    ports = [VanishingPort(written, vanish), SilentPort(written)]
    link = SerialLink('/dev/fake', 115200, lambda chunk: None, identify_timeout_s=30.0,
                      backoff_min_s=0.001, serial_factory=lambda *args, **kwargs: ports.pop(0))
    link.start()
    assert _wait(lambda: link.state is LinkState.IDENTIFYING)
    link.identify_peer()
    link.write(b'a')
    vanish.set()   # another device may be behind the path when it reopens
    assert _wait(lambda: link.stats.opens == 2 and link.state is LinkState.IDENTIFYING)
    with pytest.raises(PeerNotIdentified):
        link.write(b'b')
    link.stop()
    assert written == [b'a']


def test_a_port_refused_before_opening_is_never_opened_and_is_retried():
    opened, reports = [], []
    link = SerialLink('/dev/fake', 115200, lambda chunk: None,
                      lambda state, detail: reports.append(detail),
                      backoff_min_s=0.001, backoff_max_s=0.002,
                      open_check=lambda port: f'{port} is stale',
                      serial_factory=lambda *args, **kwargs: opened.append(args))
    link.start()
    assert _wait(lambda: link.stats.open_failures >= 3)
    link.stop()
    assert opened == [] and link.stats.last_error == '/dev/fake is stale'
    assert [r for r in reports if 'stale' in r] == ['cannot open /dev/fake: /dev/fake is stale; '
                                                    'retrying']


def test_a_later_open_failure_replaces_the_not_identified_reason():
    written, attempts = [], []

    def factory(*args, **kwargs):
        attempts.append(args[0])
        if len(attempts) > 1:
            raise serial.SerialException('could not open port: gone')
        return SilentPort(written)
    link = SerialLink('/dev/fake', 115200, lambda chunk: None, identify_timeout_s=0.02,
                      backoff_min_s=0.001, backoff_max_s=0.002, serial_factory=factory)
    link.start()
    assert _wait(lambda: link.stats.identify_timeouts == 1 and link.stats.open_failures >= 1)
    link.stop()
    assert not link.stats.last_open_unidentified and 'gone' in link.stats.last_error
