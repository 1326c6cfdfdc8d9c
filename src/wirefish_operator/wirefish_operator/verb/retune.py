# SPDX-License-Identifier: Apache-2.0
"""
`wirefish retune`: fit the CPG to a desired body wave through the tuner's retune_gait action.

The same goal as ``ros2 action send_goal --feedback /wirefish/retune_gait
wirefish_msgs/action/RetuneGait "{wave: {c1: 0.15, c2: 1.0, k: 8.0, frequency_hz: 1.0}}"``:
a live progress bar from the action's feedback on a terminal (plain lines otherwise), the
result as a table. Ctrl-C cancels the goal (the tuner stops the fit within one iteration and
applies nothing) and exits 130.
"""

import argparse
from dataclasses import dataclass
import math
import sys
import time

from wirefish_bringup.graph import DEFAULT_NAMESPACE
from wirefish_cli.ros_session import ros_session, RosSession
from wirefish_common.progress import estimate_text
from wirefish_cpg.gait_library import FitMode
from wirefish_operator.goal_sender import GoalSender

BAR_WIDTH = 30
UINT32_MAX = 2**32 - 1
CANCEL_WAIT_S = 10.0
FEEDBACK_DRAIN_S = 1.0  # how long the last feedback may trail the result (separate topics)


def count(text: str) -> int:
    """Return ``text`` as a whole number that fits the goal's uint32 fields."""
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
    parser.add_argument('--mode', choices=[mode.value for mode in FitMode],
                        default=FitMode.PHASE_FREE.value,
                        help="fit mode: the locked output (default) or the paper's literal "
                             'problem')
    parser.add_argument('--no-library', action='store_true',
                        help='always fit, even if the gait library holds this wave')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--timeout', type=float, default=120.0,
                        help='seconds to wait for the answer')


def progress_line(iteration: int, best_loss: float, total: int, estimate: str = '') -> str:
    """Return a one-line text progress bar for one feedback message (and the time left)."""
    fraction = min(max(iteration / total, 0.0), 1.0) if total > 0 else 0.0
    filled = int(round(fraction * BAR_WIDTH))
    return (f'[{"#" * filled}{"." * (BAR_WIDTH - filled)}] '
            f'iteration {iteration}/{total}  best loss {best_loss:.4f}'
            + (f'  {estimate}' if estimate else ''))


def bar_redraw(line: str) -> str:
    """Return what redraws the terminal's line as ``line``: back, clear to its end, ``line``."""
    # Without the clear, a shorter line keeps the longer one's tail ('done in 0 s' + 'ft').
    return '\r\x1b[K' + line


def feedback_line(iteration: int, best_loss: float, total: int, rmse,
                  estimate: str = '') -> str:
    """Return one plain line for one feedback message (when stderr is not a terminal)."""
    return (f'iteration {iteration}/{total} best loss {best_loss:.6g} m*s RMSE theta '
            f'{rmse[0]:.3f}/{rmse[1]:.3f} deg' + (f', {estimate}' if estimate else ''))


def result_table(result) -> str:
    """Return the tuner's result as an aligned text table."""
    params = result.params
    rows = [
        ('success', str(result.success)),
        ('message', result.message),
        ('frequency_hz', f'{params.frequency_hz:.4f}'),
        ('amplitude_1 / _2 (rad)', f'{params.amplitude[0]:+.4f} / {params.amplitude[1]:+.4f}'),
        ('w12 / w21', f'{params.w12:+.4f} / {params.w21:+.4f}'),
        ('phi12 / phi21 (rad)', f'{params.phi12:+.4f} / {params.phi21:+.4f}'),
        ('alpha', f'{params.alpha:.2f}'),
        ('loss', f'{result.loss:.5g}'),
        ('RMSE theta1 / theta2 (deg)',
         f'{result.rmse_theta_deg[0]:.4f} / {result.rmse_theta_deg[1]:.4f}'),
        ('iterations', str(result.iterations)),
        ('elapsed (s)', f'{result.elapsed_s:.3f}'),
        ('applied', str(result.applied)),
        ('from library', str(result.from_library)),
    ]
    width = max(len(name) for name, _ in rows)
    return '\n'.join(f'{name:<{width}}  {value}' for name, value in rows)


@dataclass
class _FeedbackSeen:
    """What the goal's feedback has shown so far (its callback runs on the main thread)."""

    drawn: bool = False  # a progress bar is on the terminal's line (end it before printing)
    last_iteration: int = -1
    first: tuple[float, int] | None = None  # (when, iteration) of the first feedback


def goal_of(args: argparse.Namespace, goal_type):
    """Return the action goal of the command-line options."""
    goal = goal_type()
    goal.wave.c1, goal.wave.c2, goal.wave.k = args.c1, args.c2, args.k
    goal.wave.frequency_hz = args.freq
    goal.apply = args.apply
    goal.seed = args.seed
    goal.max_iterations = args.iterations
    goal.swarm_size = args.swarm
    goal.use_library = not args.no_library
    goal.mode = args.mode
    return goal


def run(args: argparse.Namespace) -> int:
    """Run `wirefish retune`; return 0 when the tuner reports success."""
    # Ctrl-C arrives as KeyboardInterrupt here (rclpy's handler off), so the goal is canceled.
    with ros_session('wirefish_retune', args.namespace) as session:
        return _retune(args, session)


def _retune(args: argparse.Namespace, session: RosSession) -> int:
    from rclpy.action import ActionClient
    from wirefish_msgs.action import RetuneGait

    node, namespace = session.node, session.namespace
    # The goal's feedback is taken by the GoalSender (every iteration, also after the result).
    client = ActionClient(node, RetuneGait, 'retune_gait')
    terminal = sys.stderr.isatty()
    seen = _FeedbackSeen()

    def on_feedback(message) -> None:
        f = message.feedback
        seen.last_iteration = f.iteration
        if seen.first is None:
            seen.first = (time.monotonic(), f.iteration)
        first_at, first_iteration = seen.first
        # The PSO may stop early (stalled): the estimate is for all its iterations.
        estimate = estimate_text(f.iteration - first_iteration, f.max_iterations - first_iteration,
                                 time.monotonic() - first_at)
        if terminal:
            print(bar_redraw(progress_line(f.iteration, f.best_loss, f.max_iterations,
                                           estimate)), end='', file=sys.stderr, flush=True)
            seen.drawn = True
        else:
            print(feedback_line(f.iteration, f.best_loss, f.max_iterations, f.rmse_theta_deg,
                                estimate), file=sys.stderr, flush=True)

    def spin_until(done, deadline: float) -> bool:
        return session.spin_until(done, deadline - time.monotonic())

    handle = None
    try:
        if not client.wait_for_server(timeout_sec=10.0):
            print(f'wirefish retune: no {namespace}/retune_gait action: is the graph running '
                  '(wirefish up / make run)?', file=sys.stderr)
            return 1
        deadline = time.monotonic() + args.timeout
        # A goal whose answer is lost (a client that has just started) is adopted from the
        # server's status, or sent again: see goal_sender.
        sender = GoalSender(node, client, session.spin_once,
                            'retune_gait', RetuneGait)
        handle = sender.send(goal_of(args, RetuneGait.Goal), on_feedback, deadline)
        if handle is None:
            print(f'wirefish retune: no answer within {args.timeout:g} s', file=sys.stderr)
            return 1
        if sender.resent:
            print(f'wirefish retune: the tuner did not answer within {sender.answer_wait_s:g} '
                  f's; the goal was sent {sender.resent + 1} times', file=sys.stderr)
        if not handle.accepted:
            print('wirefish retune: busy: the tuner rejected the goal because a fit is '
                  'running; retry when it finishes', file=sys.stderr)
            return 1
        result_future = handle.get_result_async()
        if not spin_until(result_future.done, deadline):
            print(f'wirefish retune: no result within {args.timeout:g} s', file=sys.stderr)
            return 1
        result = result_future.result().result
        # The result can overtake the last feedback: draw it before the table.
        spin_until(lambda: seen.last_iteration >= result.iterations,
                   time.monotonic() + (FEEDBACK_DRAIN_S if result.iterations else 0.0))
        if seen.drawn:
            print(file=sys.stderr)
        if not result.success:  # nothing was fitted or applied: the reason is the answer
            print(f'wirefish retune: {result.message}', file=sys.stderr)
            return 1
        print(result_table(result))
        if result.applied:  # cpg_control's rule: a parameter set is a manual override
            print('wirefish retune: cpg_node runs this fit as a manual override; the planner '
                  'does not drive it until `wirefish hand-back`', file=sys.stderr)
        return 0 if math.isfinite(result.loss) else 1
    except KeyboardInterrupt:
        if seen.drawn:
            print(file=sys.stderr)
        if handle is not None and handle.accepted:
            canceling = handle.cancel_goal_async()
            spin_until(canceling.done, time.monotonic() + CANCEL_WAIT_S)
            print('wirefish retune: canceled (nothing applied)', file=sys.stderr)
        return 130
    finally:
        client.destroy()
