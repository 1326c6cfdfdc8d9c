# SPDX-License-Identifier: Apache-2.0
"""
A bridge writes only into the fish it was started for, and alone.

Across processes: bridge_node and fish_sim as their own processes on a real pty; the test
plays an unrelated terminal (a pty pair it holds, that never sends a frame) where needed.
"""

import os
import signal
import time

from diagnostic_msgs.msg import DiagnosticStatus
import pytest
from ros_utils import spin_until, stop_process
from wirefish_bridge.protocol import Heartbeat, Role, ServoCommand

# It mostly waits (0.23 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]


def _connected(probe, node: str = '') -> bool:
    return bool(probe.statuses(node)) and probe.last_diagnostics(node)['link_state'] == 'connected'


def test_a_second_bridge_on_the_same_device_is_refused_and_keeps_retrying(
        start_fish, start_bridge, probe, tmp_path):
    link = tmp_path / 'tty'
    start_fish(link)
    first = start_bridge(link, namespace='/fish_a')
    assert spin_until(probe.executor, lambda: _connected(probe, '/fish_a/'), 20.0)
    start_bridge(link, 'reconnect_backoff_max_s:=0.2', namespace='/fish_b')
    assert spin_until(probe.executor, lambda: len(probe.statuses('/fish_b/')) >= 2, 20.0)
    probe.spin_for(1.5)
    a, b = probe.statuses('/fish_a/')[-1], probe.statuses('/fish_b/')[-1]
    values_b = probe.last_diagnostics('/fish_b/')
    print(f'first: {a.name!r} {a.hardware_id!r} {a.message!r}\n'
          f'second: {b.name!r} {b.hardware_id!r} {b.message!r} {values_b}')
    assert _connected(probe, '/fish_a/') and a.level != DiagnosticStatus.ERROR
    assert b.level == DiagnosticStatus.ERROR and values_b['link_state'] != 'connected'
    assert f'in use by another process (pid {first.pid})' in b.message
    assert int(values_b['open_failures']) >= 2 and values_b['frames_in'] == '0'
    assert a.name != b.name and a.hardware_id != b.hardware_id
    assert all(str(link) in s.name and str(link) in s.hardware_id for s in (a, b))
    assert stop_process(first) == 0
    assert spin_until(probe.executor, lambda: _connected(probe, '/fish_b/'), 10.0)


def test_the_bridge_writes_nothing_into_a_device_that_is_not_a_fish(
        fake_device, start_bridge, probe):
    # An unrelated terminal: it never sends a frame, while servo_cmd keeps coming.
    start_bridge(fake_device.link, 'heartbeat_rate_hz:=20.0')
    assert spin_until(probe.executor, lambda: len(probe.statuses()) >= 3, 20.0)
    probe.spin_for(2.0, command=[0.3, 0.2])
    fake_device.read_available()
    status, values = probe.statuses()[-1], probe.last_diagnostics()
    print(f'{len(fake_device.received)} bytes written; {status.message!r} {values}')
    assert fake_device.received == b''
    assert status.level == DiagnosticStatus.ERROR and 'no fish heartbeat' in status.message
    assert values['frames_out'] == '0' and int(values['frames_withheld']) > 0
    # Once the device says it is a fish, the bridge talks to it.
    deadline = time.monotonic() + 10.0
    heard = []
    while not any(isinstance(m, ServoCommand) for m in heard):
        assert time.monotonic() < deadline, 'the bridge never talked to the fish'
        fake_device.send_fish_heartbeat()
        probe.spin_for(0.1, command=[0.3, 0.2])
        heard += fake_device.messages()
    assert any(isinstance(m, Heartbeat) and m.role is Role.HOST for m in heard)


def test_a_device_that_is_someone_s_terminal_is_never_opened(
        fake_device, terminal_of_a_shell, start_bridge, probe):
    start_bridge(fake_device.link)
    assert spin_until(probe.executor, lambda: len(probe.statuses()) >= 3, 20.0)
    status, values = probe.statuses()[-1], probe.last_diagnostics()
    print(f'{status.message!r}')
    fake_device.read_available()
    assert fake_device.received == b'' and values['opens'] == '0'
    assert status.level == DiagnosticStatus.ERROR
    assert f'controlling terminal of pid {terminal_of_a_shell}' in status.message


def test_a_stale_link_to_a_reused_terminal_gets_no_byte_and_a_new_fish_is_found(
        start_fish, start_bridge, probe, fake_device, tmp_path):
    link = tmp_path / 'fish-tty'
    killed = start_fish(link)
    os.killpg(killed.pid, signal.SIGKILL)   # leaves its link behind
    killed.wait()
    assert link.is_symlink()
    # The pts number is taken by an unrelated terminal (here: the test's own pty).
    os.unlink(link)
    os.symlink(os.ttyname(fake_device.slave), link)
    bridge = start_bridge(link, 'reconnect_backoff_max_s:=0.2')
    assert spin_until(probe.executor, lambda: len(probe.statuses()) >= 3, 20.0)
    fake_device.read_available()
    status = probe.statuses()[-1]
    print(f'stale link: {status.message!r}')
    assert fake_device.received == b''
    assert f'stale virtual-fish link: its owner (pid {killed.pid}) is gone' in status.message
    assert probe.last_diagnostics()['opens'] == '0'   # the terminal was not even opened
    start_fish(link)   # a new virtual fish re-points the link
    assert spin_until(probe.executor, lambda: _connected(probe) and len(probe.imu) > 10, 20.0)
    probe.spin_for(1.5, command=[0.3, -0.2])
    fake_device.read_available()
    assert fake_device.received == b''
    assert probe.command_until_measured([0.3, -0.2]), probe.servo[-1:]
    assert bridge.poll() is None
