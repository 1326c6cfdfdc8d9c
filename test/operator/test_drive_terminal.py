# SPDX-License-Identifier: Apache-2.0
"""
`wirefish drive` on a real pseudo-terminal: each key acts at once, on its own axis.

The arrows' escape sequences are written cut in two, with a pause between the halves, so that
drive reads each half on its own: the whole key must act when its last byte comes (Up faster,
Left turn left), and never as its tail's letter ('D' is no key, 'A' is no turn).
"""

import os
import pty
import sys
import time

import pytest
from ros_utils import spin_until

# It mostly waits (0.12 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

NAMESPACE = '/drive_pty'
STEP = 0.05, 0.1  # drive's default speed and turn steps (m/s, rad/s)
# (what is written, in pieces) -> the (speed, yaw rate) drive must send after it
KEYS = [
    ((b'\x1b', b'[A'), (STEP[0], 0.0)),             # Up, cut after ESC
    ((b'\x1b[', b'D'), (STEP[0], STEP[1])),          # Left, cut after the CSI
    ((b'\x1bO', b'A'), (2 * STEP[0], STEP[1])),      # Up in the application mode (SS3)
    ((b'\x1b[C',), (2 * STEP[0], 0.0)),              # Right, whole
    ((b'\x1b', b'[', b'B'), (STEP[0], 0.0)),         # Down, in three reads
]


@pytest.fixture
def cmd_vel(ros_context):
    """Yield (executor, list of (linear.x, angular.z) received on the namespace's cmd_vel)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from geometry_msgs.msg import Twist

    node = rclpy.create_node('drive_probe', namespace=NAMESPACE, context=ros_context)
    received: list[tuple[float, float]] = []
    node.create_subscription(
        Twist, 'cmd_vel', lambda m: received.append((m.linear.x, m.angular.z)),
        QoSProfile(depth=50, reliability=ReliabilityPolicy.RELIABLE))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    yield executor, received
    executor.shutdown()
    node.destroy_node()


@pytest.fixture
def terminal():
    """Yield (master fd, slave fd) of a fresh pseudo-terminal; both are closed at the end."""
    master, slave = pty.openpty()
    yield master, slave
    for fd in (master, slave):
        os.close(fd)


@pytest.mark.ros
def test_arrow_keys_cut_across_reads_act_at_once_on_their_axis(
        cmd_vel, terminal, spawn, tmp_path):
    executor, received = cmd_vel
    master, slave = terminal
    log = (tmp_path / 'drive.log').open('w')
    drive = spawn([sys.executable, '-m', 'wirefish_cli.cli', 'drive',
                   '--namespace', NAMESPACE], stdin=slave, stdout=log, stderr=log)
    assert spin_until(executor, lambda: received, 30.0), 'drive sent no cmd_vel'
    assert received[-1] == (0.0, 0.0)
    for pieces, expected in KEYS:
        for piece in pieces:
            os.write(master, piece)
            time.sleep(0.3)  # so that drive reads the pieces apart
        assert spin_until(executor, lambda: received[-1] == pytest.approx(expected), 10.0), (
            f'after {b"".join(pieces)!r}: drive sends {received[-1]}, not {expected}')
    os.write(master, b'q')
    assert drive.wait(timeout=10.0) == 0
    log.close()
