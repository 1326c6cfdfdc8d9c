# SPDX-License-Identifier: Apache-2.0
"""The QoS a topic's publishers offer, as rosbag2 Jazzy's metadata stores it."""

from rclpy.node import Node
from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness, QosReliability,
                                QosTime)
from rosbags.rosbag2.metadata import dump_qos_v9
import yaml


def _qos_time(duration) -> QosTime:
    return QosTime(*divmod(duration.nanoseconds, 10**9))


def offered_qos_yaml(node: Node, topic: str) -> str:
    """
    Return the QoS profiles ``topic``'s publishers offer, as rosbag2 Jazzy stores them (YAML).

    One profile per publisher, in metadata version 9's form (policy names, not numbers), so
    `ros2 bag play` can offer the same QoS again.
    """
    profiles = [Qos(QosHistory(p.history.value), p.depth, QosReliability(p.reliability.value),
                    QosDurability(p.durability.value), _qos_time(p.deadline),
                    _qos_time(p.lifespan), QosLiveliness(p.liveliness.value),
                    _qos_time(p.liveliness_lease_duration), p.avoid_ros_namespace_conventions)
                for p in (info.qos_profile for info in node.get_publishers_info_by_topic(topic))]
    return yaml.safe_dump(dump_qos_v9(profiles), sort_keys=False, default_flow_style=False)
