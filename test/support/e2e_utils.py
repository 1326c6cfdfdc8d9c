# SPDX-License-Identifier: Apache-2.0
"""Helpers of the end-to-end tests: the whole graph started exactly as `make run` starts it."""

import bisect
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
import math
import os
from pathlib import Path
import subprocess
import sys
import time

import psutil
from ros_utils import stop_process

NAMESPACE = '/e2e'
# Messages each stream of the rate probe keeps while the probe lags: 30 s of a 100 Hz stream.
PROBE_DEPTH = 3000
# `wirefish up` first listens DUPLICATE_CHECK_S (4 s) for the registry's nodes already running
# in its namespace. A test's graph runs on a ROS domain and in a namespace of its own
# (conftest.py), where no other graph can be found: its start skips the listen. The refusal is
# test/bringup/test_duplicate_namespace.py's.
OWN_NAMESPACE = ('--allow-duplicate',)


@dataclass
class RunningGraph:
    """A `wirefish up` process and what the tests need to talk to its graph."""

    launcher: subprocess.Popen
    env: dict[str, str]
    domain_id: int
    namespace: str
    out_dir: Path


def start_graph(domain_id: int, out_dir: Path, *options: str,
                namespace: str = NAMESPACE, swimming: bool = True) -> RunningGraph:
    """
    Start `wirefish up --sim [options]` (the launcher behind `make run`) on its own domain.

    Give each test that starts a graph a ``namespace`` of its own: a graph that is still
    stopping in the same namespace would make the new `wirefish up` refuse to start.
    ``swimming``: with --start-swimming (the tests observe a swimming fish; `make run`'s fish
    starts still until its first command).
    """
    if swimming:
        options = ('--start-swimming', *options)
    return start_launcher(domain_id, out_dir, ['--sim'], *options, namespace=namespace,
                          markers=('running:', 'recording to '))


def start_launcher(domain_id: int, out_dir: Path, target: list[str], *options: str,
                   namespace: str, timeout_s: float = 60.0,
                   markers: tuple[str, ...] = ('running:',)) -> RunningGraph:
    """
    Start `wirefish up TARGET --no-status [options]` on its own domain; return once it runs.

    It runs once a line starts with one of ``markers`` (`up --duration` says "recording to");
    a launcher that does not get there within ``timeout_s`` is stopped and its output raised.
    """
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    launcher = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', *target, '--no-status',
         *OWN_NAMESPACE, '--namespace', namespace, '--out', str(out_dir), *options],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    try:
        seen = lines_until_running(launcher, timeout_s, markers)
        if seen and seen[-1].startswith(markers):
            return RunningGraph(launcher, env, domain_id, namespace, out_dir)
    except BaseException:  # Ctrl-C or a timeout while waiting: leave no graph behind
        stop_process(launcher)
        raise
    stop_process(launcher)
    raise RuntimeError('wirefish up did not start:\n' + ''.join(seen) + launcher.stdout.read())


def lines_until_running(launcher: subprocess.Popen, timeout_s: float,
                        markers: tuple[str, ...] = ('running:',)) -> list[str]:
    """
    Return `wirefish up`'s output lines up to its first "running:" (or another marker).

    The last line holds the marker when the graph got there; otherwise the output ended or
    ``timeout_s`` passed (judged between two lines) and the lines say how far it got.
    """
    deadline = time.monotonic() + timeout_s
    seen: list[str] = []
    while time.monotonic() < deadline:
        line = launcher.stdout.readline()
        if not line:
            break
        seen.append(line)
        if line.startswith(markers):
            break
    return seen


@contextmanager
def stopped_on_exit(graph: RunningGraph,
                    timeout_s: float = 10.0) -> Iterator[list[psutil.Process]]:
    """
    Yield the graph's processes; on the way out stop it and leave nothing behind.

    The launcher gets its Ctrl-C (``stop_process``), a process it left running is killed, and
    its output is closed.
    """
    children = descendants(graph.launcher.pid)
    try:
        yield children
    finally:
        stop_process(graph.launcher, timeout_s=timeout_s)
        for child in children:
            if child.is_running():
                child.kill()
        graph.launcher.stdout.close()


def descendants(pid: int) -> list[psutil.Process]:
    """Return every live descendant process of ``pid``."""
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


class SimulatedTime:
    """
    The graph's simulated time (``<namespace>/clock``, owned by fish_sim) as a probe sees it.

    ``now()`` is the latest clock received (s), None before the first. The probe itself runs on
    the wall clock: it only reads the clock, so counting what arrives between two clock values
    measures rates in simulated time, whatever the machine's load did to the wall clock.
    """

    def __init__(self, node, namespace: str) -> None:
        """Subscribe to the clock of the graph in ``namespace`` (reliable: every step)."""
        from rosgraph_msgs.msg import Clock
        from wirefish_common.qos import reliable

        self.latest: float | None = None
        self.history: list[tuple[float, float]] = []  # (wall s, simulated s) of each /clock

        def on_clock(msg: Clock) -> None:
            self.latest = msg.clock.sec + 1e-9 * msg.clock.nanosec
            self.history.append((time.monotonic(), self.latest))
        node.create_subscription(Clock, f'{namespace.rstrip("/")}/clock', on_clock,
                                 reliable(100))

    def now(self) -> float | None:
        """Return the latest simulated time received (s), None before the first /clock."""
        return self.latest

    def at_wall(self, wall_s: float) -> float | None:
        """Return the simulated time that was current at ``wall_s`` (time.monotonic() s)."""
        index = bisect.bisect_right(self.history, (wall_s, math.inf))
        return self.history[index - 1][1] if index else None


def measure_simulated_rates(node, executor, namespace: str, window_s: float,
                            clock: SimulatedTime, wall_timeout_s: float
                            ) -> dict[str, tuple[str, float]]:
    """
    Return {topic: (type, messages per simulated second)} over ``window_s`` of /clock.

    A message with a header (or a sequence of them first: /tf, a MarkerArray) counts by its
    (first item's) stamp, the graph's simulated time when it was published, so a probe that
    falls behind on a loaded machine still counts every message of the window: it listens
    until /clock is ``LATE_S`` past the window's end and every stamped stream it heard has
    brought a stamp past the end (its queue drained up to there; within ``wall_timeout_s``),
    and each subscription keeps ``PROBE_DEPTH`` messages (30 s of the fastest stream: a queue of
    100 overflowed beside two CPU hogs; with 1,000, on a host where mypy took 15.5 CPU s, every
    100 Hz stream counted 93 % and every 50 and 10 Hz one 100 %, the mark of a queue that
    overflowed). A message without one counts at the simulated time current when the probe
    took it. Raises AssertionError naming what it waited for if /clock does not
    cover the window within ``wall_timeout_s`` of wall time.
    """
    from wirefish_common.cdr_views import CdrError, CdrReader
    from wirefish_common.topics import graph_topics, matching_qos, message_class

    topics = graph_topics(node, namespace)
    # Every stamp taken, from the first message on: judged against the window once it is set.
    # The probe's own /clock is a stream like the others (reliable, 100 deep), so on a starved
    # probe its view of the clock lags while a slow stream's queue is already drained: battery's
    # and the ground truth's first samples of the window were taken before the window opened and
    # went uncounted (battery 9.0 Hz, the ground truth 47.6 while imu/data counted 99.8).
    stamps: dict[str, list[float]] = {topic: [] for topic in topics}
    newest: dict[str, float] = {}  # the newest stamp heard of each stamped stream
    window: list[float] = []
    subscriptions = []

    def count(data: bytes, topic: str, stamped: str) -> None:
        if stamped:
            try:
                reader = CdrReader(data, topics[topic])
                if stamped == 'first_item' and reader.count('items') == 0:
                    return
                sec, nanosec = reader.stamp()
            except CdrError:
                return
            at: float | None = sec + 1e-9 * nanosec
            newest[topic] = max(newest.get(topic, -math.inf), at)
        else:
            at = clock.now()
        if at is not None:
            stamps[topic].append(at)

    for topic, type_name in topics.items():
        try:
            msg_class = message_class(type_name)
        except (ImportError, AttributeError, ValueError):
            continue
        stamped = _stamp_place(msg_class)
        subscriptions.append(node.create_subscription(
            msg_class, topic, lambda data, topic=topic, stamped=stamped: count(
                data, topic, stamped), matching_qos(node, topic, PROBE_DEPTH), raw=True))
    deadline = time.monotonic() + wall_timeout_s
    # Let the subscriptions match their publishers before the window opens.
    settle_until = time.monotonic() + 1.0
    while time.monotonic() < settle_until or clock.now() is None:
        assert time.monotonic() < deadline, 'no /clock from fish_sim: is the graph on sim time?'
        executor.spin_once(timeout_sec=0.05)
    start = clock.now() + 0.5  # half a second of simulated time to match, then count
    window[:] = [start, start + window_s]
    while clock.now() < window[1] + LATE_S:
        assert time.monotonic() < deadline, (
            f'/clock covered {max(0.0, clock.now() - start):.2f} of {window_s + LATE_S} s of '
            f'simulated time in {wall_timeout_s} s of wall time')
        executor.spin_once(timeout_sec=0.05)
    # The probe takes a message of each ready stream per turn, and /clock's newest: pinned to
    # one core beside a busy loop and a graph it had counted 417 of attitude's 500 messages of
    # the window when /clock passed its end, and 500 once drained. So it also drains each
    # stream heard in the window up to the window's end (a latched one, stamped before, is not
    # waited for; one that stops is waited for up to the deadline: its rate says so).
    while (any(window[0] <= at < window[1] for at in newest.values())
           and time.monotonic() < deadline):
        executor.spin_once(timeout_sec=0.05)
    for subscription in subscriptions:
        node.destroy_subscription(subscription)
    return {topic: (topics[topic],
                    sum(window[0] <= at < window[1] for at in stamps[topic]) / window_s)
            for topic in sorted(topics)}


# How long past a window's end (simulated s) stamped messages of the window may still arrive.
LATE_S = 1.0


def _stamp_place(msg_class) -> str:
    """Return where a message's stamp is: 'header', 'first_item' (of its first sequence), ''."""
    from wirefish_common.topics import message_class

    first = next(iter(msg_class.get_fields_and_field_types().values()), '')
    if first == 'std_msgs/Header':
        return 'header'
    if first.startswith('sequence<') and '/' in first:
        package, name = first[len('sequence<'):].split(',')[0].rstrip('>').split('/')
        item = message_class(f'{package}/msg/{name}')
        if next(iter(item.get_fields_and_field_types().values()), '') == 'std_msgs/Header':
            return 'first_item'
    return ''


# Streams a node decimates on the wall clock, not its node clock: judged as at least their
# nominal rate per simulated second (at --speed 1 simulated time runs at most at real time).
# None now: bridge_node's battery Decimator counts the node clock (graph_clock.GraphTime).
WALL_DECIMATED: frozenset[str] = frozenset()


def rate_problem(topic: str, measured: float, nominal: float, tolerance: float) -> str | None:
    """Return why ``measured`` (Hz of simulated time) is not ``topic``'s rate, or None."""
    if topic in WALL_DECIMATED:
        ok = measured >= nominal * (1.0 - tolerance)
    else:
        ok = abs(measured - nominal) <= tolerance * nominal
    return None if ok else f'{topic}: {measured:.1f} Hz of simulated time, promised {nominal:g}'
