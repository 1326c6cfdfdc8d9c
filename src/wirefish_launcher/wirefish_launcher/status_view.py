# SPDX-License-Identifier: Apache-2.0
"""
`wirefish up`'s status: every topic's rate, the link, the battery and the planner's mode.

On a terminal the block is redrawn in place about once a second while the graph runs;
otherwise it is printed once, after a measuring window. Hidden topics (a name token starting
with ``_``, such as an action's ``_action/feedback``) are left out, as ``ros2 topic list``
does. A latched topic (every publisher transient local) that holds a sample shows
``latched``, not "no msgs". Messages are taken from the subscriptions' queues at each refresh
(no executor, no callback per message), so watching costs the launcher little.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import math
import time
from typing import Any

DIAGNOSTIC_LEVELS = {0: 'OK', 1: 'WARN', 2: 'ERROR', 3: 'STALE'}
QUEUE_DEPTH = 500  # per topic between two refreshes: 1 s of the fastest stream, with room
WINDOW_S = 3.0  # the rates shown are over the last WINDOW_S seconds


def is_hidden(topic: str) -> bool:
    """Return whether ``topic`` is hidden by ROS's convention (a token starting with _)."""
    return any(token.startswith('_') for token in topic.split('/') if token)


@dataclass
class RateWindow:
    """How many messages arrived when, over the last ``window_s`` seconds."""

    window_s: float = WINDOW_S
    since: float | None = None
    _arrivals: deque = field(default_factory=deque)

    def add(self, now: float, count: int) -> None:
        """Record that ``count`` messages were taken at ``now``."""
        if self.since is None:
            self.since = now
        if count:
            self._arrivals.append((now, count))
        while self._arrivals and self._arrivals[0][0] < now - self.window_s:
            self._arrivals.popleft()

    def rate(self, now: float) -> float:
        """Return messages per second over the window (or since the first look, if shorter)."""
        if self.since is None:
            return 0.0
        span = min(self.window_s, now - self.since)
        return sum(n for t, n in self._arrivals if t >= now - self.window_s) / max(span, 1e-9)


def rate_text(rate: float, latched: bool, received: int) -> str:
    """Return a topic's rate column: '100.0 Hz', 'latched', or 'no msgs'."""
    if latched and received:
        return 'latched' if rate < 0.05 else f'{rate:.1f} Hz, latched'
    return f'{rate:.1f} Hz' if rate > 0.0 else 'no msgs'


def link_text(statuses) -> str:
    """Return the bridge's serial link from /diagnostics statuses: 'OK', 'ERROR: why'."""
    for status in statuses:
        if 'serial link' in status.name:
            level = DIAGNOSTIC_LEVELS.get(_level(status.level), str(status.level))
            return level if level == 'OK' else f'{level}: {status.message}'
    return 'no serial link diagnostics yet'


def _level(value) -> int:
    return value[0] if isinstance(value, (bytes, bytearray)) else int(value)


def battery_text(message) -> str:
    """Return '7.92 V, 85 %' from a sensor_msgs/BatteryState (NaN fields left out)."""
    parts = [f'{message.voltage:.2f} V'] if math.isfinite(message.voltage) else []
    if math.isfinite(message.percentage):
        parts.append(f'{message.percentage * 100.0:.0f} %')
    return ', '.join(parts) or 'unknown'


# What the tail does in the planner's modes that do not say it by their name alone.
MODE_MEANINGS = {
    'still': 'still: servos at neutral until the first command',
    'own_gait': 'own_gait: the CPG swims its start-up gait',
    'rest': 'rest: no swimming command, the tail at rest',
    'manual': 'manual: the CPG swims a set gait, cmd_vel not followed',
}


def planner_text(state) -> str:
    """Return the planner's mode as the status shows it: what the tail is doing."""
    return MODE_MEANINGS.get(state.mode, state.mode)


@dataclass
class _Watched:
    subscription: Any  # an rclpy Subscription (rclpy is imported only when watching)
    type_name: str
    latched: bool
    window: RateWindow
    received: int = 0
    last: object = None
    primed: bool = False  # the first take holds the backlog since subscribing: not a rate


def clock_text(real_time_factor: float | None) -> str:
    """Return the clock column: the wall clock, or simulated time at its real-time factor."""
    if real_time_factor is None:
        return 'wall'
    return f'simulated, {real_time_factor:.2f} x real time'


class SimulatedClock:
    """
    The real-time factor of the virtual fish's clock (``<namespace>/clock``) over a window.

    Simulated seconds per wall second between the first and the last clock of ``WINDOW_S``;
    None while no clock moves (the wall-clock roads: a real fish, the emulated board, a radio).
    """

    def __init__(self, node, topic: str, wall=time.monotonic) -> None:
        """Subscribe to ``topic`` from ``node`` (taken at each ``refresh``, as the topics are)."""
        from rosgraph_msgs.msg import Clock
        from rclpy.qos import qos_profile_sensor_data

        self._node, self.wall = node, wall
        self._samples: deque[tuple[float, float]] = deque()  # (wall s, simulated s)
        # Simulated seconds the clock moved forward over every clock taken (a restarted
        # fish_sim starts its clock again: the step back is not counted).
        self.advanced = 0.0
        self.moved_at = wall()  # wall s of the last forward move (or of subscribing)
        self._last: float | None = None
        self._subscription = node.create_subscription(Clock, topic, _unused,
                                                      qos_profile_sensor_data)

    def refresh(self) -> None:
        """Take the clock messages that arrived; keep the window's (wall, simulated) pairs."""
        now = self.wall()
        while True:
            got = self._subscription.handle.take_message(self._subscription.msg_type, False)
            if got is None:
                break
            stamp = got[0].clock
            simulated = stamp.sec + 1e-9 * stamp.nanosec
            if self._last is not None and simulated > self._last:
                self.advanced += simulated - self._last
                self.moved_at = now
            self._last = simulated
            self._samples.append((now, simulated))
        while len(self._samples) > 2 and self._samples[0][0] < now - WINDOW_S:
            self._samples.popleft()

    def real_time_factor(self) -> float | None:
        """Return simulated s per wall s over the window, or None without a moving clock."""
        if len(self._samples) < 2:
            return None
        (wall_0, sim_0), (wall_1, sim_1) = self._samples[0], self._samples[-1]
        if wall_1 - wall_0 < 0.5 or sim_1 < sim_0:  # a restarted fish_sim may start earlier
            return None
        return (sim_1 - sim_0) / (wall_1 - wall_0)

    def text(self) -> str:
        """Return the clock column of the header."""
        return clock_text(self.real_time_factor())

    def close(self) -> None:
        """Destroy the subscription."""
        self._node.destroy_subscription(self._subscription)


class LiveStatus:
    """Watches a namespace's topics from ``node``; ``refresh()`` then ``lines()``."""

    def __init__(self, node, namespace: str, clock=time.monotonic) -> None:
        """Subscribe to what runs now (``refresh`` subscribes to topics that appear later)."""
        self._node, self._namespace = node, namespace.rstrip('/')
        self._watched: dict[str, _Watched] = {}
        self._diagnostics: dict[str, Any] = {}  # the last status of each name seen
        self._clock = SimulatedClock(node, f'{self._namespace}/clock', clock)
        self._scan()

    def _scan(self) -> None:
        from rclpy.qos import DurabilityPolicy
        from wirefish_common.topics import graph_topics, matching_qos, message_class

        for topic, type_name in graph_topics(self._node, self._namespace or '/').items():
            if topic in self._watched or is_hidden(topic):
                continue
            try:
                msg_class = message_class(type_name)
            except (ImportError, AttributeError, ValueError):
                continue
            qos = matching_qos(self._node, topic, QUEUE_DEPTH)
            subscription = self._node.create_subscription(
                msg_class, topic, _unused, qos, raw=topic not in self._decoded())
            self._watched[topic] = _Watched(
                subscription, type_name, qos.durability == DurabilityPolicy.TRANSIENT_LOCAL,
                RateWindow())

    def _decoded(self) -> set[str]:
        """Return the topics whose content the header shows (the others are only counted)."""
        return {f'{self._namespace}/planner_state', f'{self._namespace}/battery',
                '/diagnostics'}

    def refresh(self) -> None:
        """Take what every subscription holds; subscribe to topics that appeared."""
        self._scan()
        self._clock.refresh()
        now = self._clock.wall()
        for topic, watched in self._watched.items():
            subscription = watched.subscription
            raw = topic not in self._decoded()
            count = 0
            while True:
                got = subscription.handle.take_message(subscription.msg_type, raw)
                if got is None:
                    break
                count += 1
                if not raw:
                    watched.last = got[0]
                if topic == '/diagnostics':
                    self._diagnostics.update((s.name, s) for s in got[0].status)
            watched.received += count
            watched.window.add(now, count if watched.primed else 0)
            watched.primed = True

    def close(self) -> None:
        """Destroy the subscriptions (the middleware stops keeping their samples)."""
        for watched in self._watched.values():
            self._node.destroy_subscription(watched.subscription)
        self._watched.clear()
        self._clock.close()

    def _last(self, topic: str):
        watched = self._watched.get(topic)
        return watched.last if watched is not None else None

    def header(self) -> str:
        """Return the line of the link, the battery and the planner's mode."""
        battery = self._last(f'{self._namespace}/battery')
        planner = self._last(f'{self._namespace}/planner_state')
        # /diagnostics is shared by every graph of the domain: this namespace's statuses only.
        ours = [s for name, s in self._diagnostics.items()
                if name.startswith(f'{self._namespace}/')]
        return (f'clock: {self._clock.text()} | link: {link_text(ours)}'
                f' | battery: {battery_text(battery) if battery else "no battery yet"}'
                f' | planner: {planner_text(planner) if planner else "no planner_state yet"}')

    def lines(self) -> list[str]:
        """Return the header and one line per topic (name, type, rate)."""
        now = self._clock.wall()
        rows = [self.header(), f'{"topic":<40} {"type":<38} {"rate":>14}']
        for topic in sorted(self._watched):
            watched = self._watched[topic]
            shown = rate_text(watched.window.rate(now), watched.latched, watched.received)
            rows.append(f'{topic:<40} {watched.type_name:<38} {shown:>14}')
        return rows


def _unused(_message) -> None:
    """Never called: nothing spins these subscriptions, refresh() takes their messages."""


class TerminalBlock:
    """A block of lines redrawn in place on a terminal (cursor up, clear below)."""

    def __init__(self, stream) -> None:
        """Draw on ``stream`` (a terminal)."""
        self._stream, self._height = stream, 0

    def draw(self, lines: list[str]) -> None:
        """Replace the block drawn last with ``lines``."""
        up = f'\x1b[{self._height}F' if self._height else ''
        self._stream.write(up + '\x1b[J' + '\n'.join(lines) + '\n')
        self._stream.flush()
        self._height = len(lines)

    def forget(self) -> None:
        """Leave the block as it is: what is printed next goes below it."""
        self._height = 0
