# SPDX-License-Identifier: Apache-2.0
"""
`wirefish play BAG`: publish a recorded bag's messages again, at the pace they were recorded.

The pip-only road's ``ros2 bag play``: every topic of the bag (``--topics``: some) is published
with the reliability and durability its publishers offered (metadata.yaml; latched state stays
latched), each message's bytes as recorded, in the order and with the spacing of their log
times (``--rate`` scales it). ``--remap FROM:=TO`` replaces a name prefix, so a bag of
/wirefish plays into a graph under another namespace without meeting the graph's own
publishers. The publishers are created first and given ``--delay`` seconds to be discovered;
``--wait-for-subscribers SECONDS`` waits first, at most that long, until every played topic that
is not latched has a subscriber (a late subscriber of a latched one still gets it): the first
messages then reach the graph's readers however slowly discovery goes.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import sys
import time
from typing import Any

from wirefish_cli.ros_session import ros_session

ACK_WAIT_S = 5.0  # how long the played messages may take to be acknowledged at the end
MAX_WAIT_S = 3600.0  # the longest --delay or --wait-for-subscribers
SUBSCRIBER_POLL_S = 0.05


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish play`."""
    parser.add_argument('bag', type=Path, help='rosbag2 directory (MCAP) to play')
    parser.add_argument('--rate', type=float, default=1.0,
                        help='playback speed: 2 plays twice as fast (default %(default)g)')
    parser.add_argument('--topics', nargs='+', default=None, metavar='TOPIC',
                        help='play only these topics (names as recorded)')
    parser.add_argument('--remap', action='append', default=[], metavar='FROM:=TO',
                        help='replace the name prefix FROM by TO (repeatable)')
    parser.add_argument('--delay', type=float, default=1.0,
                        help='seconds between creating the publishers and the first message '
                        '(for subscribers to match; default %(default)g)')
    parser.add_argument('--wait-for-subscribers', type=float, default=0.0, metavar='SECONDS',
                        help='before the delay, wait at most SECONDS until every played topic '
                        'that is not latched has a subscriber (default: no wait)')


def remapped(topic: str, remaps: list[tuple[str, str]]) -> str:
    """Return ``topic`` with the first remap whose prefix (a whole name token) matches."""
    for old, new in remaps:
        old = old.rstrip('/')
        if topic == old or topic.startswith(old + '/'):
            return new.rstrip('/') + topic[len(old):]
    return topic


def parse_remap(text: str) -> tuple[str, str]:
    """Return (FROM, TO) of a ``FROM:=TO`` option; ValueError if it is not one."""
    old, separator, new = text.partition(':=')
    if not separator or not old.startswith('/') or not new.startswith('/'):
        raise ValueError(f'--remap {text!r}: expected /from:=/to (absolute names)')
    return old, new


def offered_qos(bag: Path) -> dict[str, tuple[bool, bool]]:
    """Return {topic: (reliable, latched)} from the bag's metadata.yaml (empty if none)."""
    import yaml

    try:
        info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    except (OSError, KeyError, TypeError, yaml.YAMLError):
        return {}
    found = {}
    for entry in info.get('topics_with_message_count', []):
        topic = entry['topic_metadata']
        profiles = topic.get('offered_qos_profiles') or []
        if isinstance(profiles, str):  # older metadata: a YAML string
            profiles = yaml.safe_load(profiles) or []
        found[topic['name']] = (
            bool(profiles) and all(p.get('reliability') == 'reliable' for p in profiles),
            bool(profiles) and all(p.get('durability') == 'transient_local' for p in profiles))
    return found


def run(args: argparse.Namespace) -> int:
    """Run `wirefish play`; return the exit code."""
    from wirefish_common.input_checks import bag_directory_problem

    problem = bag_directory_problem(args.bag)
    if problem is None and not (math.isfinite(args.rate) and args.rate > 0.0):
        problem = f'--rate must be a finite number > 0, got {args.rate}'
    for name in ('delay', 'wait_for_subscribers'):
        value = getattr(args, name)
        if problem is None and not (math.isfinite(value) and 0.0 <= value <= MAX_WAIT_S):
            problem = (f'--{name.replace("_", "-")} must be a number of seconds from 0 to '
                       f'{MAX_WAIT_S:g}, got {value}')
    try:
        remaps = [parse_remap(text) for text in args.remap]
    except ValueError as error:
        problem = problem or str(error)
    if problem is not None:
        print(f'wirefish play: {problem}', file=sys.stderr)
        return 2
    return _play(args, remaps)


def _wait_for_acks(publishers: dict[str, Any]) -> list[str]:
    """
    Return the topics of reliable ``publishers`` whose messages a subscriber has not acked.

    Destroying a publisher drops what it has not delivered yet: without this wait the last
    message of a play was now and then never heard.
    """
    from rclpy.duration import Duration

    deadline = time.monotonic() + ACK_WAIT_S
    unacked = []
    for topic in sorted(publishers):
        left = max(0.0, deadline - time.monotonic())
        if not publishers[topic].wait_for_all_acked(Duration(nanoseconds=int(left * 1e9))):
            unacked.append(topic)
    return unacked


def _without_subscribers(publishers: dict[str, Any], waited: list[str],
                         seconds: float) -> list[str]:
    """Wait at most ``seconds`` until each of ``waited`` has a subscriber; return those without."""
    deadline = time.monotonic() + seconds
    while True:
        missing = [t for t in waited if publishers[t].get_subscription_count() == 0]
        if not missing or time.monotonic() >= deadline:
            return missing
        time.sleep(SUBSCRIBER_POLL_S)


def _play(args: argparse.Namespace, remaps: list[tuple[str, str]]) -> int:
    from mcap.reader import make_reader
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from wirefish_bag.bag_storage import storage_files
    from wirefish_common.topics import message_class
    from wirefish_common.progress import Progress

    files = storage_files(args.bag)
    qos_of = offered_qos(args.bag)
    channels: dict[str, str] = {}
    first, last = math.inf, -math.inf
    for path in files:
        with open(path, 'rb') as stream:
            summary = make_reader(stream).get_summary()
        if summary is None:
            print(f'wirefish play: {path} has no summary (a killed recording? '
                  f'`wirefish bag reindex {args.bag}` repairs it)', file=sys.stderr)
            return 1
        for channel in summary.channels.values():
            channels[channel.topic] = summary.schemas[channel.schema_id].name
        if summary.statistics is not None and summary.statistics.message_count:
            first = min(first, summary.statistics.message_start_time)
            last = max(last, summary.statistics.message_end_time)
    wanted = {t: n for t, n in channels.items() if args.topics is None or t in args.topics}
    if not wanted:
        print(f'wirefish play: none of {args.topics} is in {args.bag}', file=sys.stderr)
        return 2
    # Not sys.argv: rcl would read play's own --remap FROM:=TO as a deprecated ROS remap rule
    # (and warn); ROS arguments reach it after --ros-args only, and play takes none.
    with ros_session('wirefish_play', rcl_args=sys.argv[:1]) as session:
        node = session.node
        publishers = {}
        for topic, type_name in wanted.items():
            reliable, latched = qos_of.get(topic, (True, False))
            qos = QoSProfile(
                depth=1 if latched else 100,
                reliability=ReliabilityPolicy.RELIABLE if reliable
                else ReliabilityPolicy.BEST_EFFORT,
                durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                else DurabilityPolicy.VOLATILE)
            try:
                publishers[topic] = node.create_publisher(
                    message_class(type_name), remapped(topic, remaps), qos)
            except (ImportError, AttributeError, ValueError) as error:
                print(f'wirefish play: skipping {topic}: unknown type {type_name} ({error})',
                      file=sys.stderr)
        if args.wait_for_subscribers > 0.0:
            volatile = [t for t in publishers if not qos_of.get(t, (True, False))[1]]
            missing = _without_subscribers(publishers, volatile, args.wait_for_subscribers)
            if missing:
                names = ', '.join(publishers[t].topic_name for t in missing)
                print(f'wirefish play: no subscriber of {names} within '
                      f'{args.wait_for_subscribers:g} s: playing anyway', file=sys.stderr)
        time.sleep(args.delay)
        span_s = max(0.0, (last - first) * 1e-9) / args.rate
        progress = Progress(f'play {args.bag.name}', max(1, math.ceil(span_s)))
        started, played = time.monotonic(), 0
        for path in files:
            with open(path, 'rb') as stream:
                for _, channel, message in make_reader(stream).iter_messages(
                        topics=list(publishers), log_time_order=True):
                    due = started + (message.log_time - first) * 1e-9 / args.rate
                    wait = due - time.monotonic()
                    if wait > 0.0:
                        time.sleep(wait)
                    publishers[channel.topic].publish(bytes(message.data))
                    played += 1
                    elapsed = int(time.monotonic() - started)
                    if elapsed > progress.done:
                        progress.step(min(elapsed, progress.total), f'{played} messages')
        progress.step(progress.total, f'{played} messages')
        unacked = _wait_for_acks({t: p for t, p in publishers.items()
                                  if qos_of.get(t, (True, False))[0]})
        print(f'played {played} messages of {len(publishers)} topics from {args.bag}')
        if unacked:
            print(f'wirefish play: not every subscriber acknowledged {", ".join(unacked)} within '
                  f'{ACK_WAIT_S:.0f} s of the last message', file=sys.stderr)
        return 0
