# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the cross-process tests of cpg_node and tuner_node (their helpers: cpg_probe)."""

from collections.abc import Iterator
from pathlib import Path

from cpg_probe import LATCHED, Probe, TUNER_NODE
import pytest
from rclpy.qos import qos_profile_sensor_data
from ros_utils import probe_node
from sensor_msgs.msg import JointState
from wirefish_msgs.msg import CpgParams


@pytest.fixture
def probe(ros_context) -> Iterator[Probe]:
    """Yield a probe subscribed to servo_cmd and the latched cpg_params."""
    with probe_node('cpg_probe', ros_context) as (node, executor):
        p = Probe(node, executor)
        node.create_subscription(JointState, 'servo_cmd', p.servo.append,
                                 qos_profile_sensor_data)
        node.create_subscription(CpgParams, 'cpg_params', p.cpg_params.append, LATCHED)
        yield p


@pytest.fixture
def library_path(tmp_path: Path) -> Path:
    """Return a gait library file of this test's own (never the user's ROS home)."""
    return tmp_path / 'gaits.yaml'


@pytest.fixture
def tuner(spawn, library_path: Path):
    """Return a starter of tuner_node on this test's library (extra --ros-args as arguments)."""
    def _tuner(*ros_args: str):
        return spawn([TUNER_NODE, '--ros-args', '-p', f'library_path:={library_path}',
                      *ros_args])
    return _tuner
