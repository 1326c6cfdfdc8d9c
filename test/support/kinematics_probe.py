# SPDX-License-Identifier: Apache-2.0
"""Helpers of the kinematics node's cross-process tests: a probe node, sample generators."""

from collections.abc import Callable
from dataclasses import dataclass, field
import math
import os
import time

from ament_index_python.packages import get_package_prefix
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.srv import GetParameters, SetParametersAtomically
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_utils import spin_until
from sensor_msgs.msg import JointState
from wirefish_common.servo_joints import SERVO_JOINTS
from wirefish_msgs.msg import BodyWaveSpec

KINEMATICS_NODE = os.path.join(get_package_prefix('wirefish_kinematics'), 'lib',
                               'wirefish_kinematics', 'kinematics_node')
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
WAIT_S = 30.0  # generous limit for discovery and answers on a busy 2-core machine
ORIGIN_S = 1000  # stamps of the test's samples start here (simulated time)


@dataclass
class Probe:
    """Test-side node: publishes servo samples and the target wave, records the outputs."""

    node: object
    executor: SingleThreadedExecutor
    body: list = field(default_factory=list)
    speed: list = field(default_factory=list)
    markers: list = field(default_factory=list)
    sent: list = field(default_factory=list)  # (t s since ORIGIN_S, angles, rates)
    publishers: dict = field(default_factory=dict)

    def spin(self, seconds: float) -> None:
        """Spin for ``seconds`` of wall time."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.01)

    def wait_for(self, predicate: Callable[[], bool], what: str) -> None:
        """Spin until ``predicate()``; fail the test naming ``what`` after WAIT_S."""
        assert spin_until(self.executor, predicate, WAIT_S), f'timed out waiting for {what}'

    def wait_connected(self, topic: str = 'servo_cmd') -> None:
        """Wait until the node subscribes ``topic`` (best-effort samples are lost before)."""
        pub = self.publishers[topic]
        self.wait_for(lambda: pub.get_subscription_count() > 0, f'a subscriber of {topic}')

    def send(self, index: int, angles, rates=(0.0, 0.0), topic: str = 'servo_cmd',
             names=SERVO_JOINTS, step_ns: int = 10_000_000) -> None:
        """Publish sample number ``index``, stamped ORIGIN_S + index * step_ns."""
        msg = JointState()
        stamp_ns = index * step_ns
        msg.header.stamp.sec = ORIGIN_S + stamp_ns // 1_000_000_000
        msg.header.stamp.nanosec = stamp_ns % 1_000_000_000
        msg.name = list(names)
        msg.position = [float(a) for a in angles]
        msg.velocity = [float(r) for r in rates]
        self.publishers[topic].publish(msg)
        self.sent.append((stamp_ns * 1e-9, tuple(angles), tuple(rates)))

    def publish_target(self, c1: float, c2: float, k: float, frequency_hz: float) -> None:
        """Publish a latched target_wave."""
        self.publishers['target_wave'].publish(
            BodyWaveSpec(c1=c1, c2=c2, k=k, frequency_hz=frequency_hz))

    def call(self, client, request):
        """Call a service and return its response."""
        self.wait_for(client.service_is_ready, client.srv_name)
        future = client.call_async(request)
        self.wait_for(future.done, f'{client.srv_name} to answer')
        return future.result()

    def set_parameters(self, values: dict) -> object:
        """Set kinematics_node parameters atomically; return the SetParametersResult."""
        client = self.node.create_client(SetParametersAtomically,
                                         'kinematics_node/set_parameters_atomically')
        request = SetParametersAtomically.Request(parameters=[
            Parameter(name, value=value).to_parameter_msg() for name, value in values.items()])
        return self.call(client, request).result

    def get_parameters(self, names: list[str]) -> dict:
        """Return the node's current values of ``names``."""
        client = self.node.create_client(GetParameters, 'kinematics_node/get_parameters')
        response = self.call(client, GetParameters.Request(names=names))
        return {name: Parameter.from_parameter_msg(ParameterMsg(name=name, value=value)).value
                for name, value in zip(names, response.values)}


def stamp_s(msg) -> float:
    """Return a message's header stamp in seconds since ORIGIN_S."""
    return (msg.header.stamp.sec - ORIGIN_S) + 1e-9 * msg.header.stamp.nanosec


def locked_servo(t: float, frequency_hz: float, amplitudes=(0.38, 0.47), delta=-1.2):
    """Return (angles, rates) of locked CPG sinusoids at time t (s)."""
    w = 2 * math.pi * frequency_hz
    phases = (w * t, w * t + delta)
    return (tuple(a * math.cos(p) for a, p in zip(amplitudes, phases)),
            tuple(-a * w * math.sin(p) for a, p in zip(amplitudes, phases)))
