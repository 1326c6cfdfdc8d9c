# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the kinematics node's cross-process tests (helpers in kinematics_probe.py)."""

from collections.abc import Iterator

from kinematics_probe import KINEMATICS_NODE, LATCHED, Probe
import pytest
from rclpy.qos import qos_profile_sensor_data, QoSProfile, ReliabilityPolicy
from ros_utils import probe_node
from sensor_msgs.msg import JointState
from visualization_msgs.msg import MarkerArray
from wirefish_msgs.msg import BodyWave, BodyWaveSpec, SpeedEstimate


@pytest.fixture
def probe(ros_context) -> Iterator[Probe]:
    """Yield a probe publishing servo_cmd/servo_state/target_wave and recording the outputs."""
    with probe_node('kinematics_probe', ros_context) as (node, executor):
        p = Probe(node, executor)
        for topic in ('servo_cmd', 'servo_state'):
            p.publishers[topic] = node.create_publisher(JointState, topic,
                                                        qos_profile_sensor_data)
        p.publishers['target_wave'] = node.create_publisher(BodyWaveSpec, 'target_wave',
                                                            LATCHED)
        node.create_subscription(BodyWave, 'body_wave', p.body.append, qos_profile_sensor_data)
        node.create_subscription(SpeedEstimate, 'speed_estimate', p.speed.append,
                                 QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
        node.create_subscription(MarkerArray, 'body_wave_markers', p.markers.append,
                                 qos_profile_sensor_data)
        yield p


@pytest.fixture
def start_node(spawn):
    """Return ``start(*ros_args)``: the installed kinematics_node as a child process."""
    def _start(*ros_args: str):
        args = [KINEMATICS_NODE]
        if ros_args:
            args += ['--ros-args', *ros_args]
        return spawn(args)
    return _start
