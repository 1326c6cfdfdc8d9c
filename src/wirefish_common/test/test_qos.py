"""The shared QoS profiles have the policies their names promise."""

import pytest
from rclpy.qos import DurabilityPolicy, ReliabilityPolicy
from wirefish_common.qos import LATCHED, RELIABLE, reliable, SENSOR_DATA


@pytest.mark.parametrize('profile, reliability, durability, depth', [
    (SENSOR_DATA, ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.VOLATILE, 5),
    (RELIABLE, ReliabilityPolicy.RELIABLE, DurabilityPolicy.VOLATILE, 10),
    (LATCHED, ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL, 1),
    (reliable(1000), ReliabilityPolicy.RELIABLE, DurabilityPolicy.VOLATILE, 1000),
])
def test_each_profile_has_its_policies(profile, reliability, durability, depth):
    assert (profile.reliability, profile.durability, profile.depth) == \
        (reliability, durability, depth)
