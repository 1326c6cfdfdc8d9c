# SPDX-License-Identifier: Apache-2.0
"""
`wirefish mission FILE`: drive the planner through timed cmd_vel legs, record, plot the path.

FILE is a mission YAML (``wirefish_operator.mission_plan``) or the name of a shipped one
(``square``). It starts once the graph answers: planner_state and the ground truth heard, and
the bridge's /diagnostics saying the link is up and the fish hears the host (no
FAILSAFE_HEARTBEAT: a bridge that has not yet heard the graph's clock sends no heartbeat, and
the fish ignores every command meanwhile). The mission keeps the virtual fish's time. On
`wirefish up --sim` that is the graph's clock (``<namespace>/clock``, lockstep at its
``--speed``: a mission on ``--speed max`` takes as little wall time as the graph needs), and the
mission holds it as the planner does (``clock_hold``): no step passes its next command until
the command went, so a mission the machine starves changes nothing. On the real-time roads it
is the ground truth's stamps (the wall clock's). The legs go to ``<namespace>/cmd_vel`` at
20 Hz of that time; the whole namespace is recorded into a rosbag2 (MCAP) bag
(``wirefish_bag.recorder``, as `wirefish record`); afterwards the report PNG (x-y path from
sim/ground_truth with heading arrows, speed and yaw rate against the setpoints) and the closure
error are written and printed.
"""

from __future__ import annotations

import argparse
from collections import deque
from dataclasses import dataclass
from datetime import datetime
import math
from pathlib import Path
import shutil
import sys
import time
from typing import TYPE_CHECKING

from wirefish_cli.ros_session import graph_namespace, ros_session, RosSession

if TYPE_CHECKING:
    from rclpy.task import Future
    from wirefish_common.clock_hold import ClockHold
    from wirefish_common.progress import Progress

CMD_RATE_HZ = 20.0
CMD_PERIOD_NS = 50_000_000  # 1 / CMD_RATE_HZ: a whole number of fish_sim's 10 ms steps
DISCOVERY_TIMEOUT_S = 30.0
HINT_AFTER_S = 5.0  # of waiting for the graph, before saying what is waited for
REST_HOLD_S = 1.0  # how long the ground truth's speed stays below REST_SPEED: at rest
REST_WAIT_S = 20.0  # how much longer than the mission's rest_s leg 1 waits for it
SHIPPED = ('square',)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish mission`."""
    from wirefish_cli.api import duration_s
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
    """
    Return the YAML of ``text``: a file, or a shipped mission's name.

    Raises ValueError when it is neither, naming the shipped missions.
    """
    path = Path(text)
    if path.exists():
        return path
    if text not in SHIPPED:
        raise ValueError(f'no mission {text!r}: neither a file nor a shipped mission '
                         f'(shipped: {", ".join(SHIPPED)}; or give a mission YAML file)')
    from ament_index_python.packages import get_package_share_directory
    return Path(get_package_share_directory('wirefish_operator'), 'missions', f'{text}.yaml')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish mission`; return the exit code."""
    from wirefish_cli.api import INTERRUPTED
    from wirefish_common.progress import end_line
    from wirefish_operator.mission_plan import load_mission

    try:
        mission = load_mission(mission_path(args.mission))
        namespace = graph_namespace(args.namespace)
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
    t0, problem, interrupted, turn_gain = _drive(mission, namespace, bag_path, args.wait)
    if t0 is None:  # no leg was sent: nothing to keep
        shutil.rmtree(out, ignore_errors=True)
        for directory in created[1:]:
            if directory.exists() and not any(directory.iterdir()):
                directory.rmdir()
    if problem is not None:
        end_line()
        print(f'wirefish mission: {problem}', file=sys.stderr)
        return INTERRUPTED if interrupted else 1
    end_line()  # the legs' bar may stop short of its end: the summary starts a line of its own
    return _report(mission, namespace, bag_path, out, t0 or 0.0, turn_gain)


@dataclass
class _Run:
    """
    Where a mission run is (the fish's time, s): resting since, the first leg's start, a problem.

    ``turn_gain`` is the planner's own parameter, for judging the gain the run identifies
    (``turn_gain_answer``: the planner's answer to the question); ``planner_heard``: a
    planner_state came; ``fish_driven``: the bridge's last status says the fish hears the host;
    ``hinted``: what is waited for was said; ``progress``: the legs'
    progress, from the first leg's start; ``fish_now``: the last ground truth's stamp;
    ``sent_at``: when (the fish's time) the last command went; ``hold``: the mission's hold on
    the graph's clock (on simulated time), ``due_ns``: the clock's time of its next command.
    """

    rest_from: float | None = None
    t0: float | None = None
    problem: str | None = None
    done: bool = False
    turn_gain: float | None = None
    turn_gain_answer: Future | None = None
    planner_heard: bool = False
    fish_driven: bool = False
    hinted: bool = False
    progress: Progress | None = None
    fish_now: float | None = None
    sent_at: float = -math.inf
    hold: ClockHold | None = None
    due_ns: int | None = None


def _drive(mission, namespace: str, bag_path: Path,
           wait_s: float) -> tuple[float | None, str | None, bool, float | None]:
    """
    Send the legs, record; return (first leg's start, fish's s; problem; Ctrl-C; turn_gain).

    The start is None when no leg was sent (no graph within ``wait_s``, or interrupted first).
    Before leg 1 the fish is brought to rest (cmd_vel 0 for at least the mission's rest_s,
    until the ground truth's speed stayed below the report's REST_SPEED for a second, at most
    REST_WAIT_S more): a fish that still swims its start-up gait would start leg 1 moving.
    """
    from wirefish_common.shutdown import SignalShutdown

    signals = SignalShutdown()  # Ctrl-C stops the legs, the fish rests, the bag is closed
    with ros_session('wirefish_mission', namespace) as session:
        return _drive_in(session, signals, mission, bag_path, wait_s)


def _drive_in(session: RosSession, signals, mission, bag_path: Path,
              wait_s: float) -> tuple[float | None, str | None, bool, float | None]:
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rcl_interfaces.msg import ParameterType
    from rcl_interfaces.srv import GetParameters
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock
    from wirefish_bag.recorder import BagRecorder
    from wirefish_common.clock_hold import ClockHold
    from wirefish_common.qos import CLOCK
    from wirefish_common.progress import Progress
    from wirefish_msgs.msg import PlannerState
    from wirefish_operator.mission_report import REST_SPEED

    node, executor, namespace = session.node, session.executor, session.namespace
    # The recorder's line per topic would flood the mission's console: its warnings only.
    rclpy.logging.set_logger_level('wirefish_recorder', rclpy.logging.LoggingSeverity.WARN)
    recorder = BagRecorder(bag_path, namespace)
    signals.attach(node)
    recorder.start_thread()  # takes its messages itself, beside the executor
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    publisher = node.create_publisher(Twist, 'cmd_vel', reliable)
    run = _Run()

    def on_state(_message: PlannerState) -> None:
        run.planner_heard = True

    node.create_subscription(PlannerState, 'planner_state', on_state, reliable)
    bridge_status = f'{namespace.rstrip("/")}/bridge_node:'

    def on_diagnostics(message: DiagnosticArray) -> None:
        for status in message.status:
            if status.name.startswith(bridge_status):
                values = {pair.key: pair.value for pair in status.values}
                run.fish_driven = fish_hears_host(values)

    node.create_subscription(DiagnosticArray, '/diagnostics', on_diagnostics, reliable)
    speeds: deque[tuple[float, float]] = deque()  # (fish's s, |surge speed| m/s), last 1 s

    def on_truth(message: Odometry) -> None:
        t = _stamp(message)
        if run.fish_now is not None and t < run.fish_now - 1.0 and run.problem is None:
            run.problem = ("the virtual fish's clock went back (fish_sim restarted?): the "
                           f'mission stops; the bag so far is in {bag_path}')
            rclpy.try_shutdown()
            return
        run.fish_now = t
        speeds.append((t, abs(message.twist.twist.linear.x)))
        if (run.hold is None and run.rest_from is not None
                and t - run.sent_at >= 1.0 / CMD_RATE_HZ):
            run.sent_at = t
            drive(t)

    node.create_subscription(Odometry, 'sim/ground_truth', on_truth, reliable)

    def on_clock(message: Clock) -> None:
        """On simulated time: send each command at its step and hold the clock until it goes."""
        if run.hold is None:
            run.hold = ClockHold(node, simulated=True)
        now_ns = message.clock.sec * 1_000_000_000 + message.clock.nanosec
        if run.rest_from is None or run.done or run.problem is not None:
            return
        if run.due_ns is None or now_ns >= run.due_ns:
            drive(now_ns * 1e-9)
            if run.done:
                return
            run.due_ns = now_ns + CMD_PERIOD_NS
            run.hold.say_due(run.due_ns)

    # The graph's clock on `wirefish up --sim` (fish_sim's, lockstep); none on the real-time
    # roads, where the ground truth's stamps pace the legs.
    node.create_subscription(Clock, 'clock', on_clock, CLOCK)
    parameters = node.create_client(GetParameters, 'planner_node/get_parameters')
    truth_topic = f'{namespace.rstrip("/")}/sim/ground_truth'
    started = time.monotonic()

    def at_rest(t: float) -> bool:
        while speeds and speeds[0][0] < t - REST_HOLD_S:
            speeds.popleft()
        return bool(speeds) and t - speeds[0][0] > 0.9 * REST_HOLD_S and all(
            speed < REST_SPEED for _, speed in speeds)

    def rest(t: float) -> None:
        publisher.publish(Twist())
        answer = run.turn_gain_answer
        if answer is not None and answer.done() and answer.result() is not None:
            values = answer.result().values
            double = values and values[0].type == ParameterType.PARAMETER_DOUBLE
            run.turn_gain = values[0].double_value if double else None
        waited = t - (run.rest_from or t)
        if waited < mission.rest_s or not (at_rest(t) or waited > mission.rest_s + REST_WAIT_S):
            return
        if not at_rest(t):
            print(f'wirefish mission: the fish did not come to rest within '
                  f'{mission.rest_s + REST_WAIT_S:g} s; leg 1 starts anyway', file=sys.stderr)
        run.t0 = t
        run.progress = Progress(f'mission {mission.name}',
                                math.ceil(mission.duration_s + mission.coast_s))

    def wait_for_graph() -> None:
        """Wall-clock timer: until the graph answers; from then the fish's time drives."""
        if run.rest_from is not None or run.problem is not None:
            return
        waited = time.monotonic() - started
        if (run.planner_heard and run.fish_driven and run.fish_now is not None
                and recorder.count(truth_topic) > 0):
            run.rest_from = run.fish_now
            print(f'mission {mission.name}: {len(mission.legs)} legs, '
                  f'{mission.duration_s:.1f} s, recording to {bag_path}; the fish comes to '
                  'rest first', flush=True)
            if parameters.service_is_ready():
                request = GetParameters.Request(names=['turn_gain'])
                run.turn_gain_answer = parameters.call_async(request)
        elif waited > wait_s:
            run.problem = (f'no {_missing(run, recorder.count(truth_topic) > 0)} under '
                           f'{namespace} within {wait_s:g} s: are the graph and the planner '
                           f'running? (wirefish up --namespace {namespace}); nothing was '
                           'written')
            rclpy.try_shutdown()
        elif waited > HINT_AFTER_S and not run.hinted:
            run.hinted = True
            print(f'wirefish mission: waiting for planner_state and sim/ground_truth '
                  f'under {namespace}, and a bridge whose fish hears it (is the graph '
                  'running?)', file=sys.stderr, flush=True)

    def drive(t: float) -> None:
        """Rest the fish, then send the leg of the fish's time ``t``; stop after the coast."""
        if run.t0 is None:
            rest(t)
            return
        command = mission.command_at(t - run.t0)
        elapsed = int(t - run.t0)
        if run.progress is not None and elapsed > run.progress.done:
            run.progress.step(elapsed, _phase(mission, t - run.t0))
        if command is not None:
            msg = Twist()
            msg.linear.x, msg.angular.z = command
            publisher.publish(msg)
        elif t - run.t0 > mission.duration_s + mission.coast_s:
            run.done = True
            if run.hold is not None:
                run.hold.release()
            rclpy.try_shutdown()

    node.create_timer(1.0 / CMD_RATE_HZ, wait_for_graph)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        recorder.close()
        recorder.destroy_node()
    interrupted = run.problem is None and not run.done
    if interrupted:
        run.problem = (f'interrupted (Ctrl-C); the bag so far is in {bag_path}'
                       if run.t0 is not None
                       else 'interrupted (Ctrl-C) before the first leg; nothing was written')
    return run.t0, run.problem, interrupted, run.turn_gain


def fish_hears_host(bridge_values: dict[str, str]) -> bool:
    """
    Return whether a bridge's /diagnostics values say its fish is driven by it.

    The link is connected and the fish's status word has no FAILSAFE_HEARTBEAT (PROTOCOL.md's
    flag names in ``fish_status``, e.g. ``0x0002 (FAILSAFE_HEARTBEAT)``).
    """
    status = bridge_values.get('fish_status', 'unknown')
    return (bridge_values.get('link_state') == 'connected' and status.startswith('0x')
            and 'FAILSAFE_HEARTBEAT' not in status)


def _missing(run: _Run, truth_heard: bool) -> str:
    """Return what the mission did not hear from the graph, for its one line."""
    heard = (('planner_state', run.planner_heard), ('sim/ground_truth', truth_heard),
             ('bridge status whose fish hears the host', run.fish_driven))
    missing = [name for name, came in heard if not came]
    return ', '.join(missing) or 'answer'


def _phase(mission, t: float) -> str:
    """Return what the mission does ``t`` s after the first leg's start, for its progress."""
    if t < 0.0:
        return 'at rest before leg 1'
    for number, (start, leg) in enumerate(zip(mission.leg_starts(), mission.legs), start=1):
        if t < start + leg.duration_s:
            return (f'leg {number}/{len(mission.legs)}: {leg.speed:.2f} m/s, '
                    f'{leg.yaw_rate:+.2f} rad/s')
    return 'coasting, recording'


def _report(mission, namespace: str, bag_path: Path, out: Path, t0: float,
            turn_gain: float | None) -> int:
    import numpy as np
    from wirefish_bag.bagfile import read_bag
    from wirefish_operator.mission_report import (plot_mission, summarise, summary_text,
                                                  Track, turn_gain_text)

    topic = f'{namespace.rstrip("/")}/sim/ground_truth'
    state_topic = f'{namespace.rstrip("/")}/planner_state'
    bag = read_bag(bag_path, [topic, state_topic])
    # Header stamps, not the bag's receive times: the recorder takes its backlog in batches.
    rows = [(_stamp(m) - t0, m.pose.pose.position.x, m.pose.pose.position.y,
             2.0 * math.atan2(m.pose.pose.orientation.z, m.pose.pose.orientation.w),
             m.twist.twist.linear.x, m.twist.twist.angular.z)
            for _, m in bag.messages.get(topic, [])]
    if len(rows) < 2:
        print(f'wirefish mission: the bag {bag_path} has no {topic}: the report needs the '
              "virtual fish's ground truth", file=sys.stderr)
        return 1
    data = np.array(rows)
    track = Track(*(data[:, i] for i in range(6)))
    summary = summarise(track, mission)
    png = plot_mission(track, mission, summary, out / f'{mission.name}.png')
    print(summary_text(mission, summary))
    states = [(_stamp(m) - t0, m) for _, m in bag.messages.get(state_topic, [])]
    print(turn_gain_text(states, mission, turn_gain))
    print(f'bag: {bag_path}\nreport: {png}')
    return 0


def _stamp(message) -> float:
    """Return a message's header stamp (s)."""
    return message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
