# SPDX-License-Identifier: Apache-2.0
"""Helpers of the CPG/tuner cross-process tests: a probe node and service-call helpers."""

from dataclasses import dataclass, field
import os
import time

from ament_index_python.packages import get_package_prefix
from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.srv import GetParameters, SetParametersAtomically
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ros_utils import spin_until

CPG_NODE = os.path.join(get_package_prefix('wirefish_cpg'), 'lib', 'wirefish_cpg', 'cpg_node')
TUNER_NODE = os.path.join(get_package_prefix('wirefish_tuner'), 'lib', 'wirefish_tuner',
                          'tuner_node')
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
WAIT_S = 30.0  # generous limit for discovery and answers on a busy 2-core machine
RESEND_AFTER_S = 10.0  # a default fit takes ~0.1 s alone, a few s on the loaded machine


@dataclass
class Probe:
    """A test-side node listening to the CPG node, with blocking service helpers."""

    node: object
    executor: SingleThreadedExecutor
    servo: list = field(default_factory=list)
    cpg_params: list = field(default_factory=list)

    def call(self, client, request, timeout_s: float = WAIT_S,
             resend_after_s: float = RESEND_AFTER_S):
        """
        Call a service and return its response (fails the test after ``timeout_s``).

        A request still unanswered after ``resend_after_s`` is sent again, as a robust client
        does: rmw_fastrtps can lose the answer to a client its server has only just discovered
        (seen: the tuner fitted and stored the gait, and the probe heard nothing in 30 s). The
        first answer to any of the copies is returned.
        """
        assert spin_until(self.executor, client.service_is_ready, WAIT_S), client.srv_name
        deadline = time.monotonic() + timeout_s
        futures = [client.call_async(request)]
        while not spin_until(self.executor, lambda: any(f.done() for f in futures),
                             min(resend_after_s, max(0.0, deadline - time.monotonic()))):
            assert time.monotonic() < deadline, f'{client.srv_name} silent'
            futures.append(client.call_async(request))
        return next(f for f in futures if f.done()).result()

    def set_parameters(self, values: dict) -> object:
        """Set CPG node parameters atomically; return the SetParametersResult."""
        client = self.node.create_client(SetParametersAtomically,
                                         'cpg_node/set_parameters_atomically')
        request = SetParametersAtomically.Request(parameters=[
            Parameter(name, value=value).to_parameter_msg() for name, value in values.items()])
        return self.call(client, request).result

    def get_parameters(self, names: list[str]) -> dict:
        """Return the CPG node's current values of ``names``."""
        client = self.node.create_client(GetParameters, 'cpg_node/get_parameters')
        response = self.call(client, GetParameters.Request(names=names))
        return {name: Parameter.from_parameter_msg(ParameterMsg(name=name, value=value)).value
                for name, value in zip(names, response.values)}

    def wait_samples(self, count: int) -> None:
        """Spin until ``count`` more servo_cmd samples arrived."""
        target = len(self.servo) + count
        assert spin_until(self.executor, lambda: len(self.servo) >= target, WAIT_S), \
            f'only {len(self.servo)} servo_cmd samples'

    def trace(self, start: int = 0):
        """Return (t (T,), positions (T, 2), velocities (T, 2)) of samples from ``start``."""
        import numpy as np
        msgs = self.servo[start:]
        t = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in msgs])
        return t, np.array([m.position for m in msgs]), np.array([m.velocity for m in msgs])


def max_step_ratio(t, positions, velocities) -> float:
    """Return the largest output step over 1.5 max|rate| dt; <= 1 means no step."""
    import numpy as np
    dt = np.diff(t)
    steps = np.abs(np.diff(positions, axis=0)).max(axis=1)
    bound = 1.5 * np.abs(velocities).max() * np.maximum(dt, 1e-4)
    return float((steps / bound).max())
