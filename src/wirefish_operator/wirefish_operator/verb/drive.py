# SPDX-License-Identifier: Apache-2.0
"""
`wirefish drive`: a terminal teleop; the planner's state live on one line.

Keys: w / arrow up faster, s / arrow down slower, a / arrow left turn left (+ yaw rate,
REP-103), d / arrow right turn right, space stop (speed and turn 0), q quit (the fish rests:
cmd_vel stops and the planner's timeout brings it to rest). cmd_vel goes out at 10 Hz,
faster than the planner's 0.5 s timeout. On a full install,
`ros2 run teleop_twist_keyboard teleop_twist_keyboard --ros-args -r __ns:=/wirefish` does the
same job.
"""

from __future__ import annotations

import argparse
import codecs
from dataclasses import dataclass
import math
import os
import shutil
import sys
import time

from wirefish_cli.ros_session import graph_namespace, ros_session, RosSession

PUBLISH_HZ = 10.0
NO_GRAPH_HINT_S = 3.0  # without planner_state, when the status line says what may be wrong
ESC = '\x1b'
ARROWS = {f'{prefix}{final}': key for prefix in ('\x1b[', '\x1bO')
          for final, key in (('A', 'w'), ('B', 's'), ('D', 'a'), ('C', 'd'))}


@dataclass(frozen=True)
class DriveLimits:
    """Step and limit of each axis (m/s, rad/s)."""

    speed_step: float = 0.05
    max_speed: float = 0.4
    turn_step: float = 0.1
    max_turn: float = 0.6


def key_action(key: str, speed: float, turn: float, limits: DriveLimits
               ) -> tuple[float, float] | None:
    """Return the new (speed, yaw rate) after ``key``, or None to quit; unknown keys: no change."""
    key = ARROWS.get(key, key).lower()
    if key == 'q' or key == '\x03':  # q or Ctrl-C
        return None
    if key == 'w':
        speed = min(limits.max_speed, speed + limits.speed_step)
    elif key == 's':
        speed = max(0.0, speed - limits.speed_step)
    elif key == 'a':
        turn = min(limits.max_turn, turn + limits.turn_step)
    elif key == 'd':
        turn = max(-limits.max_turn, turn - limits.turn_step)
    elif key == ' ':
        speed, turn = 0.0, 0.0
    return round(speed, 6), round(turn, 6)


class KeyDecoder:
    """
    Keys from the terminal's bytes as they arrive: an arrow's escape sequence counts as one key.

    ``feed`` takes whatever one read returned and gives back the keys it completes; a sequence
    cut between two reads (``ESC`` now, ``[A`` next) is kept until its last byte comes, so
    it acts once, whole, and never as its tail's letters (``A`` would be a turn).
    """

    def __init__(self) -> None:
        """Start with nothing pending."""
        self._text = codecs.getincrementaldecoder('utf-8')(errors='replace')
        self._pending = ''

    def feed(self, data: bytes) -> list[str]:
        """Return the keys ``data`` completes (CSI ``ESC [ ... final``, SS3 ``ESC O x``)."""
        text = self._pending + self._text.decode(data)
        keys, i = [], 0
        while i < len(text):
            if text[i] != ESC:
                keys.append(text[i])
                i += 1
                continue
            end = _sequence_end(text, i)
            if end is None:  # cut by the read: the rest comes with the next one
                break
            keys.append(text[i:end])
            i = end
        self._pending = text[i:]
        return keys


def _sequence_end(text: str, start: int) -> int | None:
    """Return the end of the escape sequence at ``start``, or None if ``text`` cuts it."""
    if start + 1 >= len(text):
        return None
    introducer = text[start + 1]
    if introducer == 'O':  # SS3: ESC O A (arrows in the terminal's application mode)
        return start + 3 if start + 2 < len(text) else None
    if introducer != '[':
        return start + 1  # a lone ESC key, then an ordinary one
    for end in range(start + 2, len(text)):
        if '\x40' <= text[end] <= '\x7e':  # CSI's final byte (parameters come before it)
            return end + 1
    return None


def state_line(speed: float, turn: float, state, waited_s: float = 0.0,
               namespace: str = '') -> str:
    """
    Return the status line: what is sent, and the planner's state (or that none came).

    ``waited_s`` is how long drive has run without a planner_state: after NO_GRAPH_HINT_S
    the line says which graph it waits for.
    """
    sent = f'cmd_vel {speed:.2f} m/s {turn:+.2f} rad/s'
    if state is None and waited_s >= NO_GRAPH_HINT_S:
        return (f'{sent} | no planner_state in {namespace or "/"} after {waited_s:.0f} s: '
                f'is the graph running? (wirefish up --namespace {namespace or "/"})')
    if state is None:
        return f'{sent} | no planner_state yet'
    heading = '' if math.isnan(state.heading_target) else \
        f' hold {math.degrees(state.heading_target):+.0f} deg'
    line = (f'{sent} | {state.mode:<9} {state.predicted_speed:.2f} m/s at '
            f'{state.tail_beat_hz:.2f} Hz, amplitude x{state.amplitude_scale:.2f} | yaw rate '
            f'{state.yaw_rate_target:+.2f}/{state.yaw_rate_measured:+.2f} rad/s (asked/'
            f'measured), offset {state.offset:+.3f} rad{heading}')
    reason = state.clamp_reason or state.note
    return f'{line} | {reason}' if reason else line


def screen_lines(line: str, reason_shown: str, columns: int) -> tuple[str, str]:
    """
    Return (what to write, the reason now shown) for one redraw of the status line.

    The line is cut to the terminal's ``columns``; the planner's reason (its part after the
    last ' | ', a clamp or a note) is printed whole on a line of its own whenever it changes,
    above the status line, so no width cuts it.
    """
    reason = ''
    head, _, tail = line.rpartition(' | ')
    if head and not tail.startswith(('yaw rate', 'no planner_state')):
        reason = tail
    above = (f'\r\x1b[K  planner: {reason}\n' if reason and reason != reason_shown else '')
    return above + '\r\x1b[K' + line[:max(20, columns - 1)], reason


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish drive`."""
    from wirefish_bringup.graph import DEFAULT_NAMESPACE

    defaults = DriveLimits()
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--speed-step', type=float, default=defaults.speed_step,
                        help='m/s per key press')
    parser.add_argument('--max-speed', type=float, default=defaults.max_speed, help='m/s')
    parser.add_argument('--turn-step', type=float, default=defaults.turn_step,
                        help='rad/s per key press')
    parser.add_argument('--max-turn', type=float, default=defaults.max_turn, help='rad/s')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish drive` on this terminal; return the exit code."""
    namespace = graph_namespace(args.namespace)
    values = (args.speed_step, args.max_speed, args.turn_step, args.max_turn)
    if not all(math.isfinite(v) and v > 0.0 for v in values):
        print('wirefish drive: steps and limits must be finite and > 0', file=sys.stderr)
        return 2
    if not sys.stdin.isatty():
        print('wirefish drive: needs a terminal (keys are read from stdin)', file=sys.stderr)
        return 2
    with ros_session('wirefish_drive', namespace) as session:
        return _drive(_Link(session), DriveLimits(*values), namespace)


def _drive(link: _Link, limits: DriveLimits, namespace: str) -> int:
    import select
    import termios
    import tty

    fd = sys.stdin.fileno()
    decoder = KeyDecoder()
    saved = termios.tcgetattr(fd)
    speed, turn = 0.0, 0.0
    print(__doc__.strip().split('\n\n')[1].replace('\n', ' '))
    started = time.monotonic()
    reason_shown = ''
    try:
        tty.setcbreak(fd)
        while link.ok():
            ready, _, _ = select.select([fd], [], [], 1.0 / PUBLISH_HZ)
            if ready:
                # The fd, not sys.stdin: the text stream would buffer an arrow's tail where
                # select no longer sees it.
                for key in decoder.feed(os.read(fd, 1024)):
                    result = key_action(key, speed, turn, limits)
                    if result is None:
                        return 0
                    speed, turn = result
            link.send(speed, turn)
            waited = time.monotonic() - started
            line = state_line(speed, turn, link.state, waited, namespace)
            text, reason_shown = screen_lines(line, reason_shown,
                                              shutil.get_terminal_size().columns)
            sys.stdout.write(text)
            sys.stdout.flush()
    except KeyboardInterrupt:
        pass
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)
        print()
    return 0


class _Link:
    """The teleop's node: cmd_vel out, planner_state in (spun between key reads)."""

    def __init__(self, session: RosSession) -> None:
        import rclpy
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        from geometry_msgs.msg import Twist
        from wirefish_msgs.msg import PlannerState

        self._rclpy = rclpy
        self._twist = Twist
        self._session = session
        self.node = session.node
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._pub = self.node.create_publisher(Twist, 'cmd_vel', reliable)
        self.state = None
        self.node.create_subscription(PlannerState, 'planner_state', self._on_state, reliable)

    def _on_state(self, msg) -> None:
        self.state = msg

    def ok(self) -> bool:
        return self._rclpy.ok()

    def send(self, speed: float, turn: float) -> None:
        msg = self._twist()
        msg.linear.x, msg.angular.z = speed, turn
        self._pub.publish(msg)
        for _ in range(5):  # planner_state comes at 20 Hz, the keys are read at 10 Hz
            self._session.spin_once(0.0)
