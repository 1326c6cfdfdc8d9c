# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the recorder's cross-process tests: a talker, an independent listener, a seed."""

from collections.abc import Iterator
from dataclasses import dataclass, field
import os
import secrets
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, ReliabilityPolicy
from ros_utils import PEERS
from wirefish_msgs.msg import BodyWave

KILL_NAMESPACE = '/wf_kill'


@dataclass
class Listener:
    """Hears the talker beside the recorder: (counter, time.monotonic()) of each message."""

    executor: SingleThreadedExecutor
    heard: list[tuple[int, float]] = field(default_factory=list)


@pytest.fixture
def talker_namespace(spawn, python) -> str:
    """Start ros_peers' body_wave_talker (20 Hz, a counter in y[2]); return its namespace."""
    proc = spawn([python, PEERS, 'body_wave_talker', '--ros-args', '-r',
                  f'__ns:={KILL_NAMESPACE}'])
    assert proc.stdout.readline().strip() == 'ready'
    return KILL_NAMESPACE


@pytest.fixture
def listener(ros_context) -> Iterator[Listener]:
    """Yield a subscriber of the talker in this process, spun by the tests' waits."""
    node = rclpy.create_node('kill_test_listener', namespace=KILL_NAMESPACE,
                             context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    heard = Listener(executor)
    node.create_subscription(
        BodyWave, 'body_wave',
        lambda msg: heard.heard.append((int(msg.y[2]), time.monotonic())),
        QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
    yield heard
    executor.shutdown()
    node.destroy_node()


@pytest.fixture
def kill_seed() -> int:
    """Return the seed of the kill moment, printed; WIREFISH_KILL_SEED=<seed> replays one."""
    seed = int(os.environ.get('WIREFISH_KILL_SEED') or secrets.randbits(32))
    print(f'recorder kill seed: {seed} (replay: WIREFISH_KILL_SEED={seed})')
    return seed
