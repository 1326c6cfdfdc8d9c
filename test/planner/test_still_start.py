# SPDX-License-Identifier: Apache-2.0
"""
The fish starts still until its first command, then the planner starts the CPG.

With cpg_node's autostart false the planner holds the servos at neutral and says `still` until
the first command, then calls the CPG's start (in-process, on the test's own domain).

The commands: a cmd_vel that asks to move, and a manual override (a retune applied: a set of
the CPG's eq 1 parameters).
"""

from geometry_msgs.msg import Twist
import pytest
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from ros_utils import spin_until

# It mostly waits (0.28 of a core in a full run): no machine slot (machine_share.py).
pytestmark = pytest.mark.barely_loads_machine

NAMESPACE = '/still_start'
STILL_S = 2.0


@pytest.fixture
def graph(ros_context):
    """Yield (cpg node, executor, servo_cmd positions heard, planner modes heard, cmd_vel)."""
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from wirefish_cpg.cpg_node import CpgNode
    from wirefish_msgs.msg import PlannerState
    from wirefish_planner.planner_node import PlannerNode

    cpg = CpgNode(context=ros_context, namespace=NAMESPACE,
                  parameter_overrides=[Parameter('autostart', value=False)])
    planner = PlannerNode(context=ros_context, namespace=NAMESPACE)
    peer = rclpy.create_node('peer', namespace=NAMESPACE, context=ros_context)
    servo: list[tuple[float, float]] = []
    modes: list[str] = []
    peer.create_subscription(JointState, 'servo_cmd', lambda m: servo.append(tuple(m.position)),
                             qos_profile_sensor_data)
    peer.create_subscription(PlannerState, 'planner_state', lambda m: modes.append(m.mode), 10)
    cmd_vel = peer.create_publisher(Twist, 'cmd_vel', 10)
    executor = SingleThreadedExecutor(context=ros_context)
    for node in (cpg, planner, peer):
        executor.add_node(node)
    try:
        yield cpg, executor, servo, modes, cmd_vel
    finally:
        executor.shutdown()
        for node in (peer, planner, cpg):
            node.destroy_node()


def _still_for_a_while(executor, servo, modes) -> None:
    assert spin_until(executor, lambda: len(servo) > 100 * STILL_S and len(modes) > 20,
                      timeout_s=30.0)
    assert max(abs(a) for sample in servo for a in sample) == 0.0
    assert set(modes) == {'still'}, set(modes)


def _moves(servo, since: int) -> bool:
    return any(abs(a) > 0.05 for sample in servo[since:] for a in sample)


@pytest.mark.ros
def test_a_cmd_vel_that_asks_to_move_starts_the_cpg(graph):
    _, executor, servo, modes, cmd_vel = graph
    _still_for_a_while(executor, servo, modes)
    rest = Twist()  # a teleop's zeros are no command to move
    for _ in range(10):
        cmd_vel.publish(rest)
        spin_until(executor, lambda: False, timeout_s=0.05)
    since = len(servo)
    spin_until(executor, lambda: False, timeout_s=1.0)
    assert not _moves(servo, since) and modes[-1] == 'still'
    swim = Twist()
    swim.linear.x = 0.2

    def swims() -> bool:
        cmd_vel.publish(swim)
        return _moves(servo, since)

    assert spin_until(executor, swims, timeout_s=15.0)
    assert modes[-1] not in ('still', 'rest'), modes[-1]


@pytest.mark.ros
def test_a_retune_applied_starts_the_cpg(graph):
    cpg, executor, servo, modes, _ = graph
    _still_for_a_while(executor, servo, modes)
    since = len(servo)
    result = cpg.set_parameters_atomically([Parameter('frequency_hz', value=1.5),
                                            Parameter('amplitude_1', value=0.3),
                                            Parameter('amplitude_2', value=0.35)])
    assert result.successful, result.reason
    assert spin_until(executor, lambda: _moves(servo, since), timeout_s=15.0)
    assert spin_until(executor, lambda: modes[-1] == 'manual', timeout_s=5.0), modes[-1]


@pytest.mark.ros
def test_a_cpg_restarted_mid_drive_is_started_again(graph, ros_context):
    from wirefish_cpg.cpg_node import CpgNode

    cpg, executor, servo, modes, cmd_vel = graph
    swim = Twist()
    swim.linear.x = 0.2
    since = len(servo)

    def swims_since(start: int):
        def check() -> bool:
            cmd_vel.publish(swim)
            return _moves(servo, start)
        return check

    assert spin_until(executor, swims_since(since), timeout_s=15.0)
    executor.remove_node(cpg)
    cpg.destroy_node()  # the CPG is gone: its start service too
    spin_until(executor, swims_since(len(servo)), timeout_s=1.0)
    again = CpgNode(context=ros_context, namespace=NAMESPACE,
                    parameter_overrides=[Parameter('autostart', value=False)])
    executor.add_node(again)
    try:
        since = len(servo)
        assert spin_until(executor, swims_since(since), timeout_s=15.0)
    finally:
        executor.remove_node(again)
        again.destroy_node()


@pytest.mark.ros
def test_start_swimming_says_the_cpg_swims_its_own_gait(ros_context):
    # What `wirefish up --start-swimming` sets: cpg_node's autostart, no rest at start.
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from wirefish_cpg.cpg_node import CpgNode
    from wirefish_msgs.msg import PlannerState
    from wirefish_planner.planner_node import PlannerNode

    cpg = CpgNode(context=ros_context, namespace=NAMESPACE,
                  parameter_overrides=[Parameter('autostart', value=True)])
    planner = PlannerNode(context=ros_context, namespace=NAMESPACE,
                          parameter_overrides=[Parameter('rest_at_start', value=False)])
    peer = rclpy.create_node('peer', namespace=NAMESPACE, context=ros_context)
    servo: list[tuple[float, float]] = []
    modes: list[str] = []
    peer.create_subscription(JointState, 'servo_cmd', lambda m: servo.append(tuple(m.position)),
                             qos_profile_sensor_data)
    peer.create_subscription(PlannerState, 'planner_state', lambda m: modes.append(m.mode), 10)
    executor = SingleThreadedExecutor(context=ros_context)
    for node in (cpg, planner, peer):
        executor.add_node(node)
    try:
        assert spin_until(executor, lambda: _moves(servo, 0) and len(modes) > 10,
                          timeout_s=30.0)
        assert set(modes) == {'own_gait'}, set(modes)
    finally:
        executor.shutdown()
        for node in (peer, planner, cpg):
            node.destroy_node()
