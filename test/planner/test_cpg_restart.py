# SPDX-License-Identifier: Apache-2.0
"""
A CPG killed and restarted mid-drive: the planner drives the new one, nothing wedges.

cpg_node and planner_node run as their own processes (as `wirefish up` starts them); a probe
publishes cmd_vel at 20 Hz and records cpg_params (what the CPG runs) with receive times.
cpg_node is SIGKILLed while the planner drives and started again: it comes up with its
configured parameters (Table 1 at 1 Hz) and the planner's next cpg_command sets the gait again
(often before the probe hears the configured ones: cpg_params keeps only its last value). The
time from the new CPG's first servo_cmd to its first cpg_params with the planner's gait is
printed.
"""

import os
from pathlib import Path
import signal
import threading
import time

from ament_index_python.packages import get_package_prefix, get_package_share_directory
import pytest

# It mostly waits (0.25 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

NAMESPACE = '/h24_restart'
WAIT_S = 30.0
CONFIGURED_HZ = 1.0  # cpg_node's frequency_hz in the params file (Table 1 at 1 Hz)


def _node(package: str, name: str) -> list[str]:
    params = Path(get_package_share_directory('wirefish_bringup'), 'config', 'wirefish.yaml')
    return [str(Path(get_package_prefix(package), 'lib', package, name)), '--ros-args', '-r',
            f'__ns:={NAMESPACE}', '--params-file', str(params)]


def _wait(predicate, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not predicate():
        assert time.monotonic() < deadline, f'not within {WAIT_S:g} s: {what}'
        time.sleep(0.05)


@pytest.mark.ros
def test_the_planner_drives_a_restarted_cpg_on(spawn, ros_context):
    import rclpy
    from geometry_msgs.msg import Twist
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import JointState
    from wirefish_common.qos import LATCHED, SENSOR_DATA
    from wirefish_msgs.msg import CpgParams

    cpg = spawn(_node('wirefish_cpg', 'cpg_node'))
    spawn(_node('wirefish_planner', 'planner_node'))
    probe = rclpy.create_node('h24_probe', namespace=NAMESPACE, context=ros_context)
    heard: list[tuple[float, float, float]] = []  # (receive time, frequency, amplitude 1)
    probe.create_subscription(
        CpgParams, 'cpg_params',
        lambda m: heard.append((time.monotonic(), m.frequency_hz, m.amplitude[0])), LATCHED)
    servo: list[float] = []  # receive times of servo_cmd
    probe.create_subscription(JointState, 'servo_cmd', lambda _m: servo.append(time.monotonic()),
                              SENSOR_DATA)
    cmd_vel = probe.create_publisher(Twist, 'cmd_vel', 10)
    forward = Twist()
    forward.linear.x = 0.2
    probe.create_timer(0.05, lambda: cmd_vel.publish(forward))
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(probe)
    executor_thread_stop = [False]

    def spin() -> None:
        while not executor_thread_stop[0]:
            executor.spin_once(timeout_sec=0.05)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()

    def driven(since: float) -> bool:
        return any(t > since and f != CONFIGURED_HZ and a > 0.0 for t, f, a in heard)

    try:
        _wait(lambda: driven(0.0), 'the planner drives the first cpg_node')
        gait = [f for _, f, a in heard if f != CONFIGURED_HZ][-1]
        os.killpg(cpg.pid, signal.SIGKILL)
        cpg.wait()
        restarted = time.monotonic()
        spawn(_node('wirefish_cpg', 'cpg_node'))
        _wait(lambda: any(t > restarted for t in servo), 'servo_cmd of the restarted cpg_node')
        up = next(t for t in servo if t > restarted)
        _wait(lambda: driven(restarted), 'the planner drives the restarted cpg_node')
        again = next(t for t, f, a in heard if t > restarted and f != CONFIGURED_HZ and a > 0.0)
        print(f'restarted cpg_node: first servo_cmd {up - restarted:.2f} s after its start, the '
              f"planner's gait in its cpg_params {again - up:+.2f} s after that "
              f'({again - restarted:.2f} s after its start)')
        assert [f for t, f, _ in heard if t >= again][0] == pytest.approx(gait)
    finally:
        executor_thread_stop[0] = True
        spinner.join(timeout=5.0)
        executor.shutdown()
        probe.destroy_node()
