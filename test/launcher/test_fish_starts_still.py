# SPDX-License-Identifier: Apache-2.0
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


GAIT_NAMESPACE = '/starts_still_gait'
SWIMMING_PARAMS = """/**/cpg_node:
  ros__parameters:
    amplitude_1: 0.38
    amplitude_2: 0.47
/**/planner_node:
  ros__parameters:
    rest_at_start: false
"""


@pytest.mark.ros
def test_a_stopped_cpg_gives_a_gait_mode_board_no_gait_to_swim(ros_domain_id, ros_context,
                                                               tmp_path):
    """
    A params file with Table 1's amplitudes, the CPG stopped, the bridge in gait mode.

    The planner sends nothing before the first cmd_vel (``rest_at_start`` false): the CPG's
    own parameters are all the board could get.

    cpg_params (what the bridge sends to the board as its GAIT) says the CPG is at rest, the
    board acknowledges that gait and its servo_state stays at neutral until the first cmd_vel.
    """
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Twist
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from wirefish_common.qos import LATCHED
    from wirefish_msgs.msg import CpgParams

    params_file = tmp_path / 'swimming.yaml'
    params_file.write_text(SWIMMING_PARAMS, encoding='utf-8')
    graph = start_graph(ros_domain_id, tmp_path, '--drive-mode', 'gait',
                        '--params-file', str(params_file), namespace=GAIT_NAMESPACE,
                        swimming=False)
    node = rclpy.create_node('still_gait_probe', namespace=GAIT_NAMESPACE, context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    board: list[tuple[float, float]] = []
    params: list = []
    bridge: dict[str, str] = {}

    def on_diagnostics(msg) -> None:
        for status in msg.status:
            if 'bridge_node' in status.name and status.name.startswith(GAIT_NAMESPACE):
                bridge.update({kv.key: kv.value for kv in status.values})

    try:
        node.create_subscription(JointState, 'servo_state',
                                 lambda m: board.append(tuple(m.position)),
                                 qos_profile_sensor_data)
        node.create_subscription(CpgParams, 'cpg_params', params.append, LATCHED)
        node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, 10)
        # The board has the CPG's gait: sent and acknowledged (gait mode resends until then).
        assert spin_until(executor, lambda: bridge.get('gait_acknowledged') == 'True'
                          and bridge.get('drive_mode') == 'gait', timeout_s=30.0), bridge
        heard = len(board)
        assert spin_until(executor, lambda: len(board) > heard + 20 * STILL_WINDOW_S,
                          timeout_s=6 * STILL_WINDOW_S), len(board)
        # cpg_params is latched: it arrives when this reader matches its writer, which on a
        # loaded machine can come after the sensor streams matched.
        assert spin_until(executor, lambda: bool(params), timeout_s=15.0), 'no cpg_params heard'
        print(f'gait mode, CPG stopped: {len(board)} servo_state samples, largest '
              f'{max(abs(a) for s in board for a in s):.4f} rad; {len(params)} cpg_params, '
              f'amplitudes {[[float(a) for a in p.amplitude] for p in params]}; bridge gait '
              f'{bridge.get("gait_id")} acknowledged {bridge.get("gait_acknowledged")}')
        assert params and all(list(p.amplitude) == [0.0, 0.0] for p in params), params
        assert max(abs(angle) for sample in board for angle in sample) < 1e-3

        cmd_vel = node.create_publisher(Twist, 'cmd_vel', 10)
        command = Twist()
        command.linear.x = 0.15
        swimming_from = len(board)

        def swims() -> bool:
            cmd_vel.publish(command)
            return any(abs(a) > 0.05 for sample in board[swimming_from:] for a in sample)

        assert spin_until(executor, swims, timeout_s=20.0), board[-5:]
        assert any(p.amplitude[1] > 0.1 for p in params), params[-1]
    finally:
        executor.shutdown()
        node.destroy_node()
        stop_process(graph.launcher, timeout_s=15.0)
        graph.launcher.stdout.close()
