"""
`wirefish retune`: ask the tuner to fit the CPG to a desired body wave, with live progress.

The same request as ``ros2 service call /wirefish/retune_gait
wirefish_msgs/srv/RetuneGait "{wave: {c1: 0.15, c2: 1.0, k: 8.0, frequency_hz: 1.0}}"``,
with a progress bar fed by the tuner's ``retune_progress`` topic and a result table.
"""

import argparse
import math
import sys
import time

from wirefish_bringup.graph import DEFAULT_NAMESPACE, validate_namespace

BAR_WIDTH = 30
PROGRESS_DRAIN_S = 1.0  # how long the last progress messages may trail the answer
UINT32_MAX = 2**32 - 1


def count(text: str) -> int:
    """Return ``text`` as a whole number that fits the request's uint32 fields."""
    value = int(text)
    if not 0 <= value <= UINT32_MAX:
        raise argparse.ArgumentTypeError(f'must be in [0, {UINT32_MAX}], got {value}')
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish retune` (defaults: the paper's section 5.2 wave)."""
    parser.add_argument('--c1', type=float, default=0.15, help='linear envelope coefficient')
    parser.add_argument('--c2', type=float, default=1.0, help='quadratic envelope coeff. (1/m)')
    parser.add_argument('--k', type=float, default=8.0, help='body wave number (rad/m)')
    parser.add_argument('--freq', type=float, default=1.0, help='tail-beat frequency (Hz)')
    parser.add_argument('--apply', action='store_true', help='apply the fit to the CPG node')
    parser.add_argument('--seed', type=count, default=0, help='optimiser seed')
    parser.add_argument('--iterations', type=count, default=0,
                        help='PSO iterations (0: default)')
    parser.add_argument('--swarm', type=count, default=0, help='PSO particles (0: default)')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--timeout', type=float, default=120.0,
                        help='seconds to wait for the answer')


def progress_line(iteration: float, best_loss: float, total: float) -> str:
    """Return a one-line text progress bar for the tuner's progress message."""
    fraction = min(max(iteration / total, 0.0), 1.0) if total > 0 else 0.0
    filled = int(round(fraction * BAR_WIDTH))
    return (f'[{"#" * filled}{"." * (BAR_WIDTH - filled)}] '
            f'iteration {int(iteration)}/{int(total)}  best loss {best_loss:.4f}')


def result_table(response) -> str:
    """Return the tuner's answer as an aligned text table."""
    params = response.params
    rows = [
        ('success', str(response.success)),
        ('message', response.message),
        ('frequency_hz', f'{params.frequency_hz:.4f}'),
        ('amplitude_1 / _2 (rad)', f'{params.amplitude[0]:+.4f} / {params.amplitude[1]:+.4f}'),
        ('w12 / w21', f'{params.w12:+.4f} / {params.w21:+.4f}'),
        ('phi12 / phi21 (rad)', f'{params.phi12:+.4f} / {params.phi21:+.4f}'),
        ('alpha', f'{params.alpha:.2f}'),
        ('loss', f'{response.loss:.5g}'),
        ('RMSE theta1 / theta2 (deg)',
         f'{response.rmse_theta_deg[0]:.4f} / {response.rmse_theta_deg[1]:.4f}'),
        ('iterations', str(response.iterations)),
        ('elapsed (s)', f'{response.elapsed_s:.3f}'),
    ]
    width = max(len(name) for name, _ in rows)
    return '\n'.join(f'{name:<{width}}  {value}' for name, value in rows)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish retune`; return 0 when the tuner reports success."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from std_msgs.msg import Float64MultiArray
    from wirefish_msgs.srv import RetuneGait

    try:
        namespace = validate_namespace(args.namespace)
    except ValueError as error:
        print(f'wirefish retune: {error}', file=sys.stderr)
        return 2
    rclpy.init()
    node = rclpy.create_node('wirefish_retune', namespace=namespace)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    client = node.create_client(RetuneGait, 'retune_gait')
    shown: list[int] = []  # iterations drawn

    def on_progress(msg: Float64MultiArray) -> None:
        if len(msg.data) >= 3:
            print('\r' + progress_line(msg.data[0], msg.data[1], msg.data[2]), end='',
                  file=sys.stderr, flush=True)
            shown.append(int(msg.data[0]))

    node.create_subscription(Float64MultiArray, 'retune_progress', on_progress, 10)
    try:
        if not client.wait_for_service(timeout_sec=10.0):
            print(f'wirefish retune: no {namespace}/retune_gait service: is the graph running '
                  '(wirefish up / make run)?', file=sys.stderr)
            return 1
        request = RetuneGait.Request()
        request.wave.c1, request.wave.c2, request.wave.k = args.c1, args.c2, args.k
        request.wave.frequency_hz = args.freq
        request.apply = args.apply
        request.seed = args.seed
        request.max_iterations = args.iterations
        request.swarm_size = args.swarm
        time.sleep(0.3)  # let the progress subscription match before the run starts
        future = client.call_async(request)
        deadline = time.monotonic() + args.timeout
        while not future.done() and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
        if future.done() and future.result().success:
            # The answer can overtake the last progress messages: draw them before the table.
            drain_until = time.monotonic() + PROGRESS_DRAIN_S
            while (not shown or shown[-1] < future.result().iterations) \
                    and time.monotonic() < drain_until:
                executor.spin_once(timeout_sec=0.05)
        if shown:
            print(file=sys.stderr)
        if not future.done():
            print(f'wirefish retune: no answer within {args.timeout:g} s', file=sys.stderr)
            return 1
        response = future.result()
        if not response.success:  # nothing was fitted or applied: the reason is the answer
            print(f'wirefish retune: {response.message}', file=sys.stderr)
            return 1
        print(result_table(response))
        return 0 if math.isfinite(response.loss) else 1
    except KeyboardInterrupt:
        return 130
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
