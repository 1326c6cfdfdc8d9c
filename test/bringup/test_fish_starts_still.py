"""`wirefish up` on the virtual fish: servo_cmd stays at neutral until the first command."""

from e2e_utils import start_graph
import pytest
from ros_utils import spin_until, stop_process

NAMESPACE = '/starts_still'
STILL_WINDOW_S = 4.0  # of servo_cmd after the planner said it is up: 400 samples, 4 beats at 1 Hz


@pytest.mark.ros
def test_the_fish_starts_still_and_swims_at_the_first_cmd_vel(ros_domain_id, ros_context,
                                                              tmp_path):
    import rclpy
    from geometry_msgs.msg import Twist
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from wirefish_common.qos import LATCHED
    from wirefish_msgs.msg import CpgParams, PlannerState

    graph = start_graph(ros_domain_id, tmp_path, namespace=NAMESPACE, swimming=False)
    node = rclpy.create_node('still_probe', namespace=NAMESPACE, context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    servo: list[tuple[float, float]] = []
    modes: list[str] = []
    try:
        assert 'the fish starts still' in ''.join(
            graph.launcher.stdout.readline() for _ in range(1)), 'no word of the still start'
        node.create_subscription(JointState, 'servo_cmd',
                                 lambda m: servo.append(tuple(m.position)),
                                 qos_profile_sensor_data)
        node.create_subscription(PlannerState, 'planner_state', lambda m: modes.append(m.mode),
                                 10)
        # What the CPG says it runs (a bridge in gait mode sends it to the board as the gait).
        params: list = []
        node.create_subscription(CpgParams, 'cpg_params', params.append, LATCHED)
        assert spin_until(executor, lambda: servo and modes, timeout_s=30.0)
        heard = len(servo)
        assert spin_until(executor, lambda: len(servo) > heard + 100 * STILL_WINDOW_S,
                          timeout_s=4 * STILL_WINDOW_S)
        # Every sample since start-up at neutral, and every state says so.
        assert max(abs(angle) for sample in servo for angle in sample) == 0.0
        assert set(modes) == {'still'}, set(modes)
        assert params and all(list(p.amplitude) == [0.0, 0.0] for p in params), params

        cmd_vel = node.create_publisher(Twist, 'cmd_vel', 10)
        command = Twist()
        command.linear.x = 0.15
        swimming_from = len(servo)

        def swims() -> bool:
            cmd_vel.publish(command)
            return any(abs(a) > 0.05 for sample in servo[swimming_from:] for a in sample)

        assert spin_until(executor, swims, timeout_s=15.0), servo[-5:]
        assert modes[-1] not in ('still', 'rest'), modes[-1]
    finally:
        executor.shutdown()
        node.destroy_node()
        stop_process(graph.launcher, timeout_s=15.0)
        graph.launcher.stdout.close()
