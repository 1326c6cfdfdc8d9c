"""
`wirefish mission FILE`: drive the planner through timed cmd_vel legs, record, plot the path.

FILE is a mission YAML (``wirefish_planner.mission_plan``) or the name of a shipped one
(``square``). The legs go to ``<namespace>/cmd_vel`` at 20 Hz once the planner answers; the
whole namespace is recorded into a rosbag2 (MCAP) bag (``wirefish_bringup.recorder``, as
`wirefish record`); afterwards the report PNG (x-y path from sim/ground_truth with heading
arrows, speed and yaw rate against the setpoints) and the closure error are written and printed.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
import shutil
import sys

CMD_RATE_HZ = 20.0
DISCOVERY_TIMEOUT_S = 30.0
HINT_AFTER_S = 5.0  # of waiting for the graph, before saying what is waited for
SHIPPED = ('square',)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish mission`."""
    from wirefish_bringup.cli import duration_s
    from wirefish_bringup.graph import DEFAULT_NAMESPACE

    parser.add_argument('mission',
                        help=f'mission YAML file, or a shipped one: {", ".join(SHIPPED)}')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('-o', '--output', type=Path, default=None,
                        help='directory for the bag and the PNG '
                        '(default: out/missions/<name>_<time>); must not exist')
    parser.add_argument('--wait', type=duration_s, default=DISCOVERY_TIMEOUT_S,
                        help="how long to wait for the graph's planner_state and ground truth "
                        '(s, default %(default)g)')


def mission_path(text: str) -> Path:
    """Return the YAML of ``text``: a file, or a shipped mission's name."""
    path = Path(text)
    if path.exists() or text not in SHIPPED:
        return path
    from ament_index_python.packages import get_package_share_directory
    return Path(get_package_share_directory('wirefish_planner'), 'missions', f'{text}.yaml')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish mission`; return the exit code."""
    from wirefish_bringup.graph import validate_namespace
    from wirefish_planner.mission_plan import load_mission

    try:
        mission = load_mission(mission_path(args.mission))
        namespace = validate_namespace(args.namespace)
    except ValueError as error:
        print(f'wirefish mission: {error}', file=sys.stderr)
        return 2
    out = args.output or Path('out', 'missions',
                              datetime.now().strftime(f'{mission.name}_%Y%m%d_%H%M%S'))
    if out.exists():
        print(f'wirefish mission: {out} exists; choose a new -o', file=sys.stderr)
        return 2
    created = [d for d in (out, *out.parents) if not d.exists()]
    out.mkdir(parents=True)
    bag_path = out / 'bag'
    t0, problem = _drive(mission, namespace, bag_path, args.wait)
    if t0 is None:  # no leg was sent: nothing to keep
        shutil.rmtree(out, ignore_errors=True)
        for directory in created[1:]:
            if directory.exists() and not any(directory.iterdir()):
                directory.rmdir()
    if problem is not None:
        print(f'wirefish mission: {problem}', file=sys.stderr)
        return 1
    return _report(mission, namespace, bag_path, out, t0 or 0.0)


@dataclass
class _Run:
    """Where a mission run is: the first leg's start (node clock s), a problem, done."""

    t0: float | None = None
    problem: str | None = None
    done: bool = False


def _drive(mission, namespace: str, bag_path: Path,
           wait_s: float) -> tuple[float | None, str | None]:
    """
    Send the legs and record; return (first leg's start on the node clock s, problem).

    The start is None when no leg was sent (no graph within ``wait_s``, or interrupted first).
    """
    from geometry_msgs.msg import Twist
    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rclpy.signals import SignalHandlerOptions
    from wirefish_bringup.recorder import BagRecorder
    from wirefish_common.shutdown import SignalShutdown
    from wirefish_msgs.msg import PlannerState

    signals = SignalShutdown()  # Ctrl-C stops the legs, the fish rests, the bag is closed
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('wirefish_mission', namespace=namespace)
    recorder = BagRecorder(bag_path, namespace)
    signals.attach(node)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    recorder.start_thread()  # takes its messages itself, beside the executor
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    publisher = node.create_publisher(Twist, 'cmd_vel', reliable)
    heard: list[PlannerState] = []
    node.create_subscription(PlannerState, 'planner_state', heard.append, reliable)
    truth_topic = f'{namespace.rstrip("/")}/sim/ground_truth'
    run = _Run()
    started = node.get_clock().now().nanoseconds * 1e-9
    hinted: list[float] = []

    def now() -> float:
        return node.get_clock().now().nanoseconds * 1e-9

    def tick() -> None:
        t = now()
        if run.t0 is None:
            if heard and recorder.count(truth_topic) > 0:
                run.t0 = t + mission.rest_s
                print(f'mission {mission.name}: {len(mission.legs)} legs, '
                      f'{mission.duration_s:.1f} s, recording to {bag_path}', flush=True)
            elif t - started > wait_s:
                run.problem = (f'no planner_state and sim/ground_truth under {namespace} '
                               f'within {wait_s:g} s: are the graph and the planner running? '
                               f'(wirefish up --namespace {namespace}); nothing was written')
                rclpy.try_shutdown()
            elif t - started > HINT_AFTER_S and not hinted:
                hinted.append(t)
                print(f'wirefish mission: waiting for planner_state and sim/ground_truth '
                      f'under {namespace} (is the graph running?)', file=sys.stderr, flush=True)
            return
        command = mission.command_at(t - run.t0)
        if command is not None:
            msg = Twist()
            msg.linear.x, msg.angular.z = command
            publisher.publish(msg)
        elif t - run.t0 > mission.duration_s + mission.coast_s:
            run.done = True
            rclpy.try_shutdown()

    node.create_timer(1.0 / CMD_RATE_HZ, tick)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        recorder.close()
        executor.shutdown()
        recorder.destroy_node()
        node.destroy_node()
        rclpy.try_shutdown()
    if run.problem is None and not run.done:
        run.problem = (f'interrupted; the bag so far is in {bag_path}' if run.t0 is not None
                       else 'interrupted before the first leg; nothing was written')
    return run.t0, run.problem


def _report(mission, namespace: str, bag_path: Path, out: Path, t0: float) -> int:
    import math

    import numpy as np
    from wirefish_bringup.bagfile import read_bag
    from wirefish_planner.mission_report import (plot_mission, summarise, summary_text,
                                                 Track, turn_gain_text)

    topic = f'{namespace.rstrip("/")}/sim/ground_truth'
    state_topic = f'{namespace.rstrip("/")}/planner_state'
    bag = read_bag(bag_path, [topic, state_topic])
    rows = [(t - t0, m.pose.pose.position.x, m.pose.pose.position.y,
             2.0 * math.atan2(m.pose.pose.orientation.z, m.pose.pose.orientation.w),
             m.twist.twist.linear.x, m.twist.twist.angular.z)
            for t, m in bag.messages.get(topic, [])]
    if len(rows) < 2:
        print(f'wirefish mission: the bag {bag_path} has no {topic}: the report needs the '
              "virtual fish's ground truth", file=sys.stderr)
        return 1
    data = np.array(rows)
    track = Track(*(data[:, i] for i in range(6)))
    summary = summarise(track, mission)
    png = plot_mission(track, mission, summary, out / f'{mission.name}.png')
    print(summary_text(mission, summary))
    print(turn_gain_text(bag.messages.get(state_topic, [])))
    print(f'bag: {bag_path}\nreport: {png}')
    return 0
