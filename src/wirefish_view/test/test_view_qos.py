# SPDX-License-Identifier: Apache-2.0
"""The view's subscription QoS matches the publishers it found, or any when it found none."""

from types import SimpleNamespace

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from wirefish_view.view_node import _qos_of, resubscribe_qos


def _publisher(reliability, durability=DurabilityPolicy.VOLATILE):
    return SimpleNamespace(qos_profile=QoSProfile(depth=1, reliability=reliability,
                                                  durability=durability))


def test_with_no_publisher_discovered_the_view_subscribes_best_effort():
    assert _qos_of([]).reliability == ReliabilityPolicy.BEST_EFFORT


def test_a_best_effort_publisher_gets_a_best_effort_subscription():
    publishers = [_publisher(ReliabilityPolicy.BEST_EFFORT)]
    assert _qos_of(publishers).reliability == ReliabilityPolicy.BEST_EFFORT


def test_latched_reliable_publishers_get_a_latched_reliable_subscription():
    qos = _qos_of([_publisher(ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)])
    assert qos.reliability == ReliabilityPolicy.RELIABLE
    assert qos.durability == DurabilityPolicy.TRANSIENT_LOCAL


def test_a_subscription_made_before_a_latched_publisher_was_found_is_made_again_latched():
    held = _qos_of([])
    qos = resubscribe_qos(held, [_publisher(ReliabilityPolicy.RELIABLE,
                                            DurabilityPolicy.TRANSIENT_LOCAL)])
    assert qos is not None and qos.durability == DurabilityPolicy.TRANSIENT_LOCAL


def test_a_subscription_that_matches_its_publishers_is_kept():
    latched = [_publisher(ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)]
    assert resubscribe_qos(_qos_of(latched), latched) is None
    stream = [_publisher(ReliabilityPolicy.BEST_EFFORT)]
    assert resubscribe_qos(_qos_of([]), stream) is None


def test_a_subscription_whose_publishers_are_gone_is_kept():
    latched = [_publisher(ReliabilityPolicy.RELIABLE, DurabilityPolicy.TRANSIENT_LOCAL)]
    assert resubscribe_qos(_qos_of(latched), []) is None
