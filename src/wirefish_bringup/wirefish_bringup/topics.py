"""Discovering the graph's topics and subscribing to them without knowing their types ahead."""

import importlib

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness, QosReliability,
                                QosTime)
from rosbags.rosbag2.metadata import dump_qos_v9
import yaml

DIAGNOSTICS_TOPIC = '/diagnostics'


ACTION_MESSAGES = ('_FeedbackMessage', '_SendGoal_Request', '_SendGoal_Response',
                   '_GetResult_Request', '_GetResult_Response')


def message_class(type_name: str) -> type:
    """
    Return the Python class of a ROS message type such as ``sensor_msgs/msg/Imu``.

    An action's hidden types (``pkg/action/Name_FeedbackMessage``, on its ``_action/feedback``
    topic) are classes of the action's ``Impl``.
    """
    package, kind, name = type_name.split('/')
    module = importlib.import_module(f'{package}.{kind}')
    if kind == 'action':
        for suffix in ACTION_MESSAGES:
            if name.endswith(suffix):
                impl = getattr(module, name[:-len(suffix)]).Impl
                return getattr(impl, suffix[1:].replace('_', ''))
    return getattr(module, name)


def graph_topics(node: Node, namespace: str) -> dict[str, str]:
    """
    Return {topic: type} for the topics under ``namespace`` plus /diagnostics.

    Only topics that have a publisher count (a subscriber alone makes no data), and the ROS
    infrastructure topics (parameter events, rosout) are left out.
    """
    prefix = namespace.rstrip('/') + '/'
    topics = {}
    for name, types in node.get_topic_names_and_types():
        if not (name.startswith(prefix) or name == DIAGNOSTICS_TOPIC):
            continue
        if name.endswith(('/parameter_events', '/rosout')) or name == '/rosout':
            continue
        if node.count_publishers(name) == 0:
            continue
        topics[name] = types[0]
    return topics


def matching_qos(node: Node, topic: str, depth: int) -> QoSProfile:
    """
    Return a subscription QoS compatible with every publisher of ``topic``.

    Like rosbag2: reliable only when all publishers are reliable (a reliable subscription does
    not match a best-effort publisher), transient-local only when all publishers are (so latched
    state is received), and a deep queue so a slow moment loses nothing.
    """
    infos = node.get_publishers_info_by_topic(topic)
    reliable = bool(infos) and all(
        info.qos_profile.reliability == ReliabilityPolicy.RELIABLE for info in infos)
    latched = bool(infos) and all(
        info.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for info in infos)
    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


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
