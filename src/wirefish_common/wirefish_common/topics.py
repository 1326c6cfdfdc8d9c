# SPDX-License-Identifier: Apache-2.0
"""Discovering the graph's topics and subscribing to them without knowing their types ahead."""

import importlib

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

DIAGNOSTICS_TOPIC = '/diagnostics'
# On the virtual fish's clock, a node whose timer must see every period (the planner, the
# kinematics) says here when its next tick is due (std_msgs/Header: the time, its name):
# fish_sim holds the clock there until it answers again (clock_hold, wirefish_sim.lockstep).
LOCKSTEP_HOLD_TOPIC = 'lockstep/next_tick'


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
