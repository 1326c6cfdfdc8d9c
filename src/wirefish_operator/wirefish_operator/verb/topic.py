# SPDX-License-Identifier: Apache-2.0
"""
`wirefish topic list|echo|hz`: the ``ros2 topic`` verbs for machines without ros2cli.

``list`` prints every topic on this ROS domain (``-t``: with its type; hidden topics such as an
action's ``_action/...`` only with ``--include-hidden-topics``). ``echo TOPIC`` prints each
message as YAML, separated by ``---`` (``--once``: the first only; ``--field a.b``: one field),
with a QoS that matches the topic's publishers (latched state is received). ``hz TOPIC``
prints the rate every second, as ``ros2 topic hz`` does. A relative name is taken in
``--namespace`` (default /wirefish): ``wirefish topic hz servo_cmd``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
import difflib
import enum
import math
import sys
import time

from wirefish_cli.ros_session import ros_session, RosSession

DISCOVERY_S = 2.0  # how long to listen for the graph before answering
WAIT_S = 10.0  # how long echo and hz wait for the topic to appear


class TopicVerb(enum.StrEnum):
    """The verbs of `wirefish topic`, as `ros2 topic` names them."""

    LIST = 'list'
    ECHO = 'echo'
    HZ = 'hz'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare `wirefish topic list | echo | hz` and their options."""
    from wirefish_bringup.graph import DEFAULT_NAMESPACE

    verbs = parser.add_subparsers(dest='verb', required=True, metavar='VERB')
    helps = {TopicVerb.LIST: 'the topics on this ROS domain',
             TopicVerb.ECHO: 'print the messages of a topic as YAML',
             TopicVerb.HZ: "print a topic's rate every second"}
    listing, echo, hz = (verbs.add_parser(verb.value, help=text, description=text)
                         for verb, text in helps.items())
    listing.add_argument('-t', '--show-types', action='store_true', help='show each type too')
    listing.add_argument('--include-hidden-topics', action='store_true',
                         help='also topics with a token starting with _ (actions)')
    for sub in (echo, hz):
        sub.add_argument('topic', help='topic name (relative: in --namespace)')
        sub.add_argument('--namespace', default=DEFAULT_NAMESPACE,
                         help='namespace of a relative topic name (default %(default)s)')
    echo.add_argument('--once', action='store_true', help='print the first message, then exit')
    echo.add_argument('--field', default=None,
                      help='print only this field (dotted, e.g. twist.linear.x)')
    hz.add_argument('--window', type=int, default=10000,
                    help='messages the statistics are over (default %(default)s)')


def full_name(topic: str, namespace: str) -> str:
    """Return ``topic`` as an absolute name (a relative one in ``namespace``)."""
    if topic.startswith('/'):
        return topic
    return f'{namespace.rstrip("/")}/{topic}'


def missing_topic_text(topic: str, names: list[str]) -> str | None:
    """
    Return why ``topic`` cannot be echoed when the graph around it is known, else None.

    The graph is known when its namespace has topics: a name that is not among them is a
    typo or a node that is not running (the closest names are offered, as ros2cli's "does not
    appear to be published yet" does not). An empty namespace may only be undiscovered yet.
    """
    if topic in names:
        return None
    namespace = topic.rsplit('/', 1)[0] + '/'
    if not any(name.startswith(namespace) for name in names if name != topic):
        return None
    close = difflib.get_close_matches(topic, names, n=3)
    hint = f'; did you mean {" or ".join(close)}?' if close else ''
    return (f'topic {topic} does not exist{hint} (wirefish topic list shows what there is)')


def plain(value):
    """Return a message (or field) as plain Python values: dicts, lists, numbers, text."""
    if hasattr(value, 'get_fields_and_field_types'):
        return {name: plain(getattr(value, name)) for name in value.get_fields_and_field_types()}
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    if hasattr(value, 'tolist'):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [plain(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def field_of(message, path: str | None):
    """Return the field ``path`` (dotted) of ``message``, or the message for None."""
    for name in (path.split('.') if path else []):
        if not hasattr(message, name):
            raise AttributeError(f'no field {name!r} in {type(message).__name__}')
        message = getattr(message, name)
    return message


def rate_line(times: list[float]) -> str:
    """Return ros2 topic hz's lines for receive ``times`` (s): rate, min, max, std dev."""
    import numpy as np

    gaps = np.diff(np.array(times))
    return (f'average rate: {1.0 / gaps.mean():.3f}\n'
            f'\tmin: {gaps.min():.3f}s max: {gaps.max():.3f}s std dev: {gaps.std():.5f}s '
            f'window: {len(times)}')


class _Probe:
    """A node of its own on the graph (the verb's session), spun by hand."""

    def __init__(self, session: RosSession) -> None:
        self.node = session.node
        self.executor = session.executor

    def spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=min(0.1, max(0.0, end - time.monotonic())))

    def find(self, topic: str, waiting: Callable[[], None]) -> tuple[str | None, str | None]:
        """
        Listen for ``topic`` up to WAIT_S; return (its type, None) once it has a publisher.

        Return (None, why) once the graph around it has been known for DISCOVERY_S without it
        (``missing_topic_text``: a typo, or a node that is not running), and (None, None) at
        WAIT_S. A graph discovered late (a loaded machine, a graph still starting) is judged
        DISCOVERY_S after it appeared, not when the first DISCOVERY_S ended. ``waiting`` is
        called once, after DISCOVERY_S, if no graph was heard by then.
        """
        start = time.monotonic()
        known_since: float | None = None
        said_waiting = False
        while True:
            types = dict(self.node.get_topic_names_and_types())
            if topic in types and self.node.count_publishers(topic):
                return types[topic][0], None
            now = time.monotonic()
            missing = missing_topic_text(topic, list(types))
            if missing is None:
                known_since = None
            elif known_since is None:
                known_since = now
            if known_since is not None and now >= max(start, known_since) + DISCOVERY_S:
                return None, missing
            if now >= start + WAIT_S:
                return None, None
            if known_since is None and not said_waiting and now >= start + DISCOVERY_S:
                waiting()
                said_waiting = True
            self.spin_for(0.1)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish topic ...`; return the exit code."""
    with ros_session('wirefish_topic') as session:
        return _run(_Probe(session), args)


def _run(probe: _Probe, args: argparse.Namespace) -> int:
    if args.verb == TopicVerb.LIST:
        return _list(probe, args)
    topic = full_name(args.topic, args.namespace)

    def waiting() -> None:
        print(f'wirefish topic {args.verb}: waiting up to {WAIT_S:g} s for a publisher of '
              f'{topic} (Ctrl-C stops)', file=sys.stderr, flush=True)

    type_name, missing = probe.find(topic, waiting)
    if missing is not None:  # the graph is there, the topic is not: say so
        print(f'wirefish topic {args.verb}: {missing}', file=sys.stderr)
        return 1
    if type_name is None:
        print(f'wirefish topic {args.verb}: no publisher of {topic} within {WAIT_S:g} s '
              '(wirefish topic list shows what there is)', file=sys.stderr)
        return 1
    return (_echo if args.verb == TopicVerb.ECHO else _hz)(probe, topic, type_name, args)


def _list(probe: _Probe, args: argparse.Namespace) -> int:
    from wirefish_launcher.status_view import is_hidden

    probe.spin_for(DISCOVERY_S)
    for name, types in sorted(probe.node.get_topic_names_and_types()):
        if is_hidden(name) and not args.include_hidden_topics:
            continue
        print(f'{name} [{", ".join(types)}]' if args.show_types else name)
    return 0


def _subscribe(probe: _Probe, topic: str, type_name: str, callback, raw: bool = False):
    from wirefish_common.topics import matching_qos, message_class

    return probe.node.create_subscription(message_class(type_name), topic, callback,
                                          matching_qos(probe.node, topic, 100), raw=raw)


def _echo(probe: _Probe, topic: str, type_name: str, args: argparse.Namespace) -> int:
    import yaml

    got: list = []
    _subscribe(probe, topic, type_name, got.append)
    while True:
        probe.executor.spin_once(timeout_sec=0.1)
        while got:
            try:
                value = field_of(got.pop(0), args.field)
            except AttributeError as error:
                print(f'wirefish topic echo: {error}', file=sys.stderr)
                return 2
            print(yaml.safe_dump(plain(value), sort_keys=False, default_flow_style=False)
                  .rstrip('\n') + '\n---', flush=True)
            if args.once:
                return 0


def _hz(probe: _Probe, topic: str, type_name: str, args: argparse.Namespace) -> int:
    times: list[float] = []
    _subscribe(probe, topic, type_name, lambda _data: times.append(time.monotonic()), raw=True)
    shown = time.monotonic()
    while True:
        probe.executor.spin_once(timeout_sec=0.1)
        del times[:-max(2, args.window)]
        if time.monotonic() - shown >= 1.0:
            shown = time.monotonic()
            print(rate_line(times) if len(times) > 1 else 'no new messages', flush=True)
