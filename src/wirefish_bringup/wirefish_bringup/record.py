"""`wirefish record`: record every wirefish topic and /diagnostics into a rosbag2 (MCAP) bag."""

import argparse
from datetime import datetime
from pathlib import Path
import sys

from wirefish_bringup.cli import duration_s
from wirefish_bringup.graph import DEFAULT_NAMESPACE, validate_namespace
from wirefish_bringup.sequence_gaps import SequenceGaps

NOTHING_TIMEOUT_S = 30.0


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
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    from wirefish_bringup.recorder import BagRecorder
    from wirefish_common.shutdown import SignalShutdown

    try:
        namespace = validate_namespace(args.namespace)
    except ValueError as error:
        print(f'wirefish record: {error}', file=sys.stderr)
        return 2
    bag_path = args.output or Path('out', 'bags',
                                   datetime.now().strftime('wirefish_%Y%m%d_%H%M%S'))
    if bag_path.exists() and not args.resume:
        print(f'wirefish record: {bag_path} exists; choose a new -o (or --resume)',
              file=sys.stderr)
        return 2
    bag_path.parent.mkdir(parents=True, exist_ok=True)
    signals = SignalShutdown()  # Ctrl-C between callbacks: the bag is closed cleanly
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        recorder = BagRecorder(bag_path, namespace, resume=args.resume)
    except (OSError, ValueError) as error:  # not a bag, or one that cannot be recovered
        rclpy.try_shutdown()
        print(f'wirefish record: {error}', file=sys.stderr)
        return 2
    signals.attach(recorder)
    if args.duration is not None:
        started_ns = recorder.get_clock().now().nanoseconds

        def stop_when_done() -> None:
            now = recorder.get_clock().now().nanoseconds
            first = recorder.first_message_ns
            # Discovery can take a few seconds on a loaded machine: the duration counts from
            # the first message, with a bound for a graph that never publishes anything.
            if (first is not None and now - first >= args.duration * 1e9) or \
                    now - started_ns >= (args.duration + NOTHING_TIMEOUT_S) * 1e9:
                rclpy.try_shutdown()
        recorder.create_timer(0.02, stop_when_done)
    try:
        rclpy.spin(recorder)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        recorder.close()
        counts = dict(recorder.counts)
        lost = dict(recorder.lost)
        sequences = dict(recorder.sequences)
        recorder.destroy_node()
        rclpy.try_shutdown()
    print(recording_summary(bag_path, counts, lost, sequences), flush=True)
    return 0


def recording_summary(bag_path: Path, counts: dict[str, int], lost: dict[str, int],
                      sequences: dict[str, SequenceGaps]) -> str:
    """
    Return what was written and what never arrived, per topic.

    'lost in transport' is the middleware's own count; 'missing' counts the numbers absent from
    each publisher's sequence between its first and last sample in the bag (every cause of loss;
    not checked on a topic where a second publisher appeared).
    """
    checked = {t: s for t, s in sequences.items() if not s.ambiguous}
    lines = [f'wrote {sum(counts.values())} messages on {len(counts)} topics to {bag_path}; '
             f"lost in transport: {sum(lost.values())}; missing from the publishers' "
             f'sequences: {sum(s.missing for s in checked.values())}']
    for topic, count in sorted(counts.items()):
        missing = (f'missing {checked[topic].missing}' if topic in checked
                   else 'several publishers: sequence not checked')
        lines.append(f'  {topic:<40} {count:>7} (lost {lost[topic]}, {missing})')
    return '\n'.join(lines)
