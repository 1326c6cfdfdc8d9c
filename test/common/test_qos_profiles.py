# SPDX-License-Identifier: Apache-2.0
"""
The shared QoS profiles (wirefish_common.qos) deliver what their names promise, through DDS.

One node in this process publishes and subscribes on this test's own domain. A reader "behind"
is one whose executor is not spun while the samples are published: what it then takes is what
its profile kept for it.
"""

import time

import pytest
from ros_utils import probe_node, spin_until
from std_msgs.msg import Int32
from wirefish_common.qos import COMMAND, LATCHED, RELIABLE, reliable, SENSOR_DATA

# It mostly waits (0.03 of a core in a full run): no machine slot (machine_share.py).
pytestmark = [pytest.mark.ros, pytest.mark.barely_loads_machine]

DELIVERY_S = 0.5  # how long the published samples are given to reach the reader's history
QUIET_S = 0.5  # a reader that took nothing for this long has taken everything it kept


@pytest.fixture
def probe(ros_context):
    with probe_node('qos_probe', ros_context) as node_and_executor:
        yield node_and_executor


def _take_all(executor, heard: list[int]) -> list[int]:
    """Spin until nothing more arrives; return every value heard, in order."""
    while True:
        count = len(heard)
        if not spin_until(executor, lambda: len(heard) > count, timeout_s=QUIET_S):
            return heard


def _heard_by_a_reader_behind(probe, topic: str, profile, count: int) -> list[int]:
    """Publish 1..count to a matched reader that is not spun meanwhile; return what it takes."""
    node, executor = probe
    heard: list[int] = []
    publisher = node.create_publisher(Int32, topic, profile)
    subscription = node.create_subscription(Int32, topic, lambda m: heard.append(m.data),
                                            profile)
    assert spin_until(executor, lambda: publisher.get_subscription_count() == 1
                      and subscription.get_publisher_count() == 1, timeout_s=10.0)
    for value in range(1, count + 1):
        publisher.publish(Int32(data=value))
    time.sleep(DELIVERY_S)
    return _take_all(executor, heard)


def test_a_latched_topic_gives_a_late_joiner_the_last_value(probe):
    node, executor = probe
    publisher = node.create_publisher(Int32, 'latched', LATCHED)
    for value in (1, 2, 3):
        publisher.publish(Int32(data=value))
    heard: list[int] = []
    node.create_subscription(Int32, 'latched', lambda m: heard.append(m.data), LATCHED)
    assert spin_until(executor, lambda: heard, timeout_s=10.0), 'the late joiner got nothing'
    assert _take_all(executor, heard) == [3]


def test_a_command_reader_behind_takes_only_the_latest_command(probe):
    assert _heard_by_a_reader_behind(probe, 'command', COMMAND, 5) == [5]


def test_a_reliable_reader_behind_takes_each_of_ten_samples_in_order(probe):
    assert _heard_by_a_reader_behind(probe, 'reliable', RELIABLE, 10) == list(range(1, 11))


def test_a_reliable_profile_of_a_depth_keeps_that_many_latest_samples(probe):
    assert _heard_by_a_reader_behind(probe, 'deep', reliable(50), 60) == list(range(11, 61))


def test_a_sensor_reader_behind_takes_only_the_latest_five_samples(probe):
    assert _heard_by_a_reader_behind(probe, 'sensor', SENSOR_DATA, 20) == list(range(16, 21))
