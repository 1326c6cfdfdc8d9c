# SPDX-License-Identifier: Apache-2.0
"""`wirefish record`: record every wirefish topic and /diagnostics into a rosbag2 (MCAP) bag."""

import argparse
from datetime import datetime
import math
from pathlib import Path
import sys

from wirefish_bag.sequence_gaps import loss_line, recording_account, TopicAccount
from wirefish_bringup.graph import DEFAULT_NAMESPACE
from wirefish_cli.api import duration_s, UsageError
from wirefish_cli.ros_session import graph_namespace, ros_session
from wirefish_common.progress import end_line, Progress

NOTHING_TIMEOUT_S = 30.0
# How long discovery may take before an empty namespace is said (a running node's topics were
# discovered within 0 to 2.3 s on the loaded 2-core machine).
EMPTY_NAMESPACE_WARNING_S = 4.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish record`."""
    parser.add_argument('-o', '--output', type=Path, default=None,
                        help='bag directory (default: out/bags/wirefish_<time>); must not exist '
                        'unless --resume')
    parser.add_argument('--resume', action='store_true',
                        help='if the bag exists (left by a killed recorder), reindex it and '
                        'record on into its next file')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--duration', type=duration_s, default=None,
                        help='record this many seconds from the first message received '
                        '(default: until Ctrl-C)')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish record`; return the process exit code."""
    from wirefish_bag.recorder import BagRecorder
    from wirefish_common.shutdown import SignalShutdown

    namespace = graph_namespace(args.namespace)
    bag_path = args.output or Path('out', 'bags',
                                   datetime.now().strftime('wirefish_%Y%m%d_%H%M%S'))
    if bag_path.exists() and not args.resume:
        print(f'wirefish record: {bag_path} exists; choose a new -o (or --resume)',
              file=sys.stderr)
        return 2
    bag_path.parent.mkdir(parents=True, exist_ok=True)
    # Ctrl-C and SIGTERM set a flag the recording loop reads between two takes: the readers
    # are drained and the bag is closed cleanly.
    signals = SignalShutdown()
    # On a terminal its 'recording <topic>' lines would break the bar: the summary lists them.
    progress_on_terminal = sys.stderr.isatty()

    def make_recorder(namespace: str) -> BagRecorder:
        try:
            return BagRecorder(bag_path, namespace, resume=args.resume,
                               announce=not progress_on_terminal)
        except (OSError, ValueError) as error:  # not a bag, or one that cannot be recovered
            raise UsageError(str(error)) from None

    with ros_session('wirefish_recorder', namespace, make_node=make_recorder) as session:
        accounts = _record(session.node, namespace, args, bag_path, signals,
                           progress_on_terminal)
    end_line()
    print(recording_summary(bag_path, accounts, namespace), flush=True)
    return 0


def _record(recorder, namespace: str, args: argparse.Namespace, bag_path: Path, signals,
            progress_on_terminal: bool) -> dict:
    """Record until the duration or a stop signal; return the topics' accounts."""
    import time

    started_ns = time.time_ns()
    progress = (Progress(f'record {bag_path.name}', math.ceil(args.duration))
                if args.duration is not None else None)
    empty_checked = False

    def stopped() -> bool:
        nonlocal empty_checked
        if signals.requested:
            return True
        if not empty_checked and time.time_ns() - started_ns >= EMPTY_NAMESPACE_WARNING_S * 1e9:
            empty_checked = True
            warning = empty_namespace_warning(recorder, namespace)
            if warning is not None:
                if progress_on_terminal and progress is not None and progress.done:
                    print(file=sys.stderr)  # below the bar, not into it
                print(f'wirefish record: warning: {warning}', file=sys.stderr, flush=True)
        if args.duration is None or progress is None:
            return False
        now, first = time.time_ns(), recorder.first_message_ns
        recorded_s = 0 if first is None else int((now - first) * 1e-9)
        if recorded_s > progress.done:  # counted from the first message, as the duration is
            progress.step(min(recorded_s, progress.total), f'{recorder_count()} messages')
        # Discovery can take a few seconds on a loaded machine: the duration counts from
        # the first message, with a bound for a graph that never publishes anything.
        return (first is not None and now - first >= args.duration * 1e9) or \
            now - started_ns >= (args.duration + NOTHING_TIMEOUT_S) * 1e9

    def recorder_count() -> int:
        return recorder.total_count()

    try:
        recorder.record(stopped)
    finally:
        recorder.close()
    return dict(recorder.accounts)


def empty_namespace_warning(node, namespace: str) -> str | None:
    """Return a warning if no topic of ``namespace`` is on the graph (a typo?), else None."""
    prefix = namespace.rstrip('/') + '/'
    topics = [name for name, _ in node.get_topic_names_and_types()]
    if any(name.startswith(prefix) for name in topics if name != '/diagnostics'):
        return None
    others = sorted({ns for _, ns in node.get_node_names_and_namespaces()
                     if ns not in ('/', namespace)})
    where = (f'namespaces with nodes: {", ".join(others)}' if others
             else 'no other namespace has nodes either: is the graph running, on this '
             'ROS_DOMAIN_ID?')
    return f'no topic under {namespace} (only /diagnostics is recorded); {where}'


def recording_summary(bag_path: Path, accounts: dict[str, TopicAccount],
                      namespace: str | None = None) -> str:
    """
    Return what was written, what never arrived and how late it came, per topic; then the loss.

    'missing' counts the numbers absent from each publisher's sequence between its first and
    last sample in the bag: every cause of loss (in transport, a reader's history overrun); not
    checked on a topic where a second publisher appeared. 'lag' is the longest a message waited
    between its publication and the bag.
    """
    checked = {t: a.sequence for t, a in accounts.items() if not a.sequence.ambiguous}
    total_missing = sum(s.missing for s in checked.values())
    lines = [f'wrote {sum(a.count for a in accounts.values())} messages on {len(accounts)} '
             f"topics to {bag_path}; missing from the publishers' sequences: {total_missing}"]
    for topic, account in sorted(accounts.items()):
        missing = (f'missing {checked[topic].missing}' if topic in checked
                   else 'several publishers: sequence not checked')
        lag = 'latched' if account.latched else f'lag max {account.lag_max_ns * 1e-9:.2f} s'
        lines.append(f'  {topic:<40} {account.count:>7} ({missing}, {lag})')
    if namespace is not None and not any(t.startswith(namespace.rstrip('/') + '/')
                                         for t in accounts):
        lines.append(f'recording: no topic under {namespace} (only '
                     f'{", ".join(sorted(accounts)) or "nothing"}): is the namespace right?')
    else:
        lines.append(loss_line(recording_account(accounts)))
    return '\n'.join(lines)
