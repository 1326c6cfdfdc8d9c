# SPDX-License-Identifier: Apache-2.0
"""
fish_sim with three links: three virtual fish in one process, each on its own pty.

Each fish is driven over its own pty with pyserial (its own servo command) and must answer
there with its own servos; with --ros each publishes its own sim/ground_truth under its name.
"""

import os
from pathlib import Path
import select
import time

from ament_index_python.packages import get_package_prefix
import pytest
from ros_utils import spin_until
import serial
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ServoCommand, Status, Telemetry

BIN = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim'
# It mostly waits (0.23 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]
NAMES = ('fish_1', 'fish_2', 'fish_3')
NAMESPACE = '/sim_fleet'


def _wait_for_links(proc, links, timeout_s=15.0):
    deadline = time.monotonic() + timeout_s
    while not all(link.is_symlink() for link in links):
        assert proc.poll() is None, proc.stdout.read()
        assert time.monotonic() < deadline, 'fish_sim opened no pty for every fish'
        time.sleep(0.02)


def _drive(ports, commands, seconds):
    """Write each port its command (None: nothing) and a heartbeat every 20 ms; read all."""
    encoder, decoders = FrameEncoder(), [StreamDecoder() for _ in ports]
    telemetry = [[] for _ in ports]
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for k, port in enumerate(ports):
            if commands[k] is not None:
                port.write(encoder.encode(ServoCommand(*commands[k]))
                           + encoder.encode(Heartbeat()))
            telemetry[k] += [f.message for f in decoders[k].feed(port.read(4096))
                             if isinstance(f.message, Telemetry)]
        time.sleep(0.02)
    return telemetry


def test_three_fish_of_one_process_each_answer_on_their_own_pty(spawn, tmp_path):
    links = [tmp_path / f'tty_{name}' for name in NAMES]
    proc = spawn([str(BIN / 'fish_sim'), *(a for link in links for a in ('--link', str(link))),
                  '--command-timeout', '0.3'])
    _wait_for_links(proc, links)
    assert len({link.resolve() for link in links}) == len(NAMES)
    commands = [(0.1, -0.1), (0.3, 0.2), (-0.4, 0.5)]
    ports = [serial.Serial(str(link), 115200, timeout=0) for link in links]
    try:
        driven = _drive(ports, commands, 1.5)
        for k, received in enumerate(driven):
            assert len(received) > 50, f'fish {k} sent {len(received)} telemetry frames'
            last = received[-1]
            assert (last.servo_1, last.servo_2) == pytest.approx(commands[k], abs=1e-3)
            assert not last.status & Status.FAILSAFE_COMMAND
        # One fish's host goes quiet: that fish alone goes neutral, the others swim on.
        stopped, *quiet = _drive(ports, [None, *commands[1:]], 1.0)
        assert stopped[-1].status & Status.FAILSAFE_COMMAND
        assert abs(stopped[-1].servo_1) + abs(stopped[-1].servo_2) < 1e-3
        for k, received in enumerate(quiet, start=1):
            assert (received[-1].servo_1, received[-1].servo_2) == pytest.approx(
                commands[k], abs=1e-3)
    finally:
        for port in ports:
            port.close()


def test_each_fish_of_a_fleet_publishes_its_own_ground_truth(spawn, tmp_path, ros_context):
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor

    links = [tmp_path / f'tty_{name}' for name in NAMES]
    proc = spawn([str(BIN / 'fish_sim'), *(a for link in links for a in ('--link', str(link))),
                  '--ros', '--ros-args', '-r', f'__ns:={NAMESPACE}'])
    _wait_for_links(proc, links)
    node = rclpy.create_node('fleet_probe', context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    frames = {name: set() for name in NAMES}
    for name in NAMES:
        node.create_subscription(
            Odometry, f'{NAMESPACE}/{name}/sim/ground_truth',
            lambda msg, name=name: frames[name].add((msg.header.frame_id, msg.child_frame_id)),
            10)
    try:
        assert spin_until(executor, lambda: all(frames.values()), 20.0), frames
    finally:
        executor.remove_node(node)
        node.destroy_node()
        executor.shutdown()
    for name in NAMES:
        assert frames[name] == {(f'{name}/odom', f'{name}/base_link')}


@pytest.mark.parametrize('flags, says', [
    (['--link', 'a', '--link', 'a'], 'of its own'),
    (['--link', 'a', '--link', 'b', '--fish', 'x'], '1 --fish names for 2 fish'),
    (['--link', 'a', '--link', 'b', '--fish', 'x', '--fish', 'x'], 'name of its own'),
    (['--link', 'a', '--fish', '1x'], "--fish '1x'"),
])
def test_a_fleet_of_bad_flags_ends_with_one_line_and_exit_2(spawn, tmp_path, flags, says):
    proc = spawn([str(BIN / 'fish_sim'), *flags], cwd=tmp_path)
    out, _ = proc.communicate(timeout=30)
    assert proc.returncode == 2 and says in out, out
    assert not any(tmp_path.iterdir())  # no device link was made


def test_each_fish_of_a_fleet_reopens_its_own_device_and_answers_there(spawn, tmp_path):
    links = [tmp_path / f'tty_{name}' for name in NAMES[:2]]
    proc = spawn([str(BIN / 'fish_sim'), *(a for link in links for a in ('--link', str(link))),
                  '--reopen-every', '1.0', '--reopen-count', '1', '--reopen-delay', '0.3'])
    _wait_for_links(proc, links)
    output, deadline = b'', time.monotonic() + 20.0
    fd = proc.stdout.fileno()  # unbuffered reads: select sees every byte not yet read
    while output.count(b': reopened as ') < len(links):  # each fish says so on stderr
        remaining = deadline - time.monotonic()
        assert remaining > 0 and select.select([fd], [], [], remaining)[0], output
        output += os.read(fd, 4096)
    reopened = {line.split(':')[0] for line in output.decode().splitlines()
                if ': reopened as ' in line}
    assert reopened == {f'fish_sim {name}' for name in NAMES[:2]}
    assert all(link.is_symlink() for link in links)
    assert len({link.resolve() for link in links}) == len(links)
    ports = [serial.Serial(str(link), 115200, timeout=0) for link in links]
    try:
        commands = [(0.2, 0.1), (-0.3, 0.4)]
        for k, received in enumerate(_drive(ports, commands, 1.0)):
            assert (received[-1].servo_1, received[-1].servo_2) == pytest.approx(
                commands[k], abs=1e-3)
    finally:
        for port in ports:
            port.close()
