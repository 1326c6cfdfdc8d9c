"""
`wirefish up`: start one fish's whole graph, show its status, run until Ctrl-C, stop cleanly.

The launcher for machines without `ros2 launch`; `launch/wirefish.launch.py` starts the same
graph (see `wirefish_bringup.graph`) on a full install.
"""

import argparse
from datetime import datetime
from pathlib import Path
import signal
import sys
import time

from wirefish_bringup.cli import duration_s
from wirefish_bringup.compose import NODE_CLASSES as COMPOSED_NODES
from wirefish_bringup.graph import (DEFAULT_NAMESPACE, fish_graph, NodeSpec, sim_tty_link,
                                    validate_namespace)
from wirefish_bringup.supervisor import remove_stale_link, Supervisor, wait_for_path

STATUS_WINDOW_S = 3.0
STOP_GRACE_S = 10.0  # after a Ctrl-C during start-up, how long the nodes may take to be up
DEVICE_TIMEOUT_S = 15.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish up`."""
    target = parser.add_mutually_exclusive_group()
    target.add_argument('--sim', action='store_true', default=True,
                        help='drive the virtual fish on a pseudo-terminal (default)')
    target.add_argument('--port', help='serial device of a real fish, e.g. /dev/ttyUSB0')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE, help='ROS namespace')
    parser.add_argument('--duration', type=duration_s, default=None,
                        help='run this many seconds, record a bag and write a report')
    parser.add_argument('--params-file', type=Path, default=None,
                        help='parameter YAML (default: the installed config/wirefish.yaml)')
    parser.add_argument('--out', type=Path, default=Path('out'),
                        help='where run logs, bags and reports go (default: ./out)')
    parser.add_argument('--single-process', action='store_true',
                        help="run the fish's four ROS nodes in one process (wirefish compose)")
    parser.add_argument('--no-status', action='store_true', help='skip the topic-rate table')


def _wait_ready(namespace: str, node_names: list[str], show_status: bool,
                stop_requested: list, timeout_s: float = 30.0) -> str | None:
    """
    Wait until every node of the graph is on the ROS graph; return the status table or None.

    A node is "up" once it is discoverable (its rclpy.init and constructor are done), so a
    Ctrl-C after "running:" always reaches nodes that handle it cleanly.
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    from wirefish_bringup.monitor import measure_rates, settle_discovery

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('wirefish_status', namespace=namespace)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    expected = {f'{namespace.rstrip("/")}/{name}' for name in node_names}

    def discovered() -> set[str]:
        return {f'{ns.rstrip("/")}/{name}' for name, ns in node.get_node_names_and_namespaces()}

    try:
        deadline = time.monotonic() + timeout_s
        while not expected <= discovered():
            if stop_requested and deadline > time.monotonic() + STOP_GRACE_S:
                # A node interrupted while still importing dies of the SIGINT (exit -2, a
                # KeyboardInterrupt trace): let every node finish starting, then stop them all.
                print('wirefish up: stopping as soon as every node has started',
                      file=sys.stderr)
                deadline = time.monotonic() + STOP_GRACE_S
            if time.monotonic() > deadline:
                missing = ', '.join(sorted(expected - discovered()))
                return None if stop_requested else f'not up after {timeout_s:g} s: {missing}'
            executor.spin_once(timeout_sec=0.1)
        if stop_requested:
            return None
        if not show_status:
            return ''
        settle_discovery(node, executor, namespace, should_stop=lambda: bool(stop_requested))
        rates = measure_rates(node, executor, namespace, STATUS_WINDOW_S,
                              should_stop=lambda: bool(stop_requested))
        if stop_requested:  # Ctrl-C while the table was measured: stop now, no table
            return None
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    lines = [f'nodes: {", ".join(sorted(expected))}',
             f'{"topic":<40} {"type":<38} {"rate":>9}']
    for topic, (type_name, rate) in rates.items():
        shown = f'{rate:7.1f} Hz' if rate > 0 else 'no msgs'  # idle, or latched only
        lines.append(f'{topic:<40} {type_name:<38} {shown:>9}')
    return '\n'.join(lines)


def run(args: argparse.Namespace) -> int:
    """Run `wirefish up`; return the process exit code."""
    try:
        namespace = validate_namespace(args.namespace)
        sim = args.port is None
        specs = fish_graph(namespace, sim=sim, port=args.port, params_file=args.params_file,
                           single_process=args.single_process)
    except ValueError as error:
        print(f'wirefish up: {error}', file=sys.stderr)
        return 2
    if args.port is not None and not Path(args.port).exists():
        print(f'wirefish up: {args.port} does not exist (yet): the bridge keeps retrying until '
              'it appears; /diagnostics and its log say why it cannot open it', file=sys.stderr)
    stamp = datetime.now().strftime('%Y%m%d_%H%M%S')
    run_dir = (args.out / f'run_{stamp}').resolve()
    supervisor = Supervisor(run_dir / 'logs')
    stop_requested = []

    def request_stop(signum, _frame) -> None:
        stop_requested.append(signum)

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    bag_path = run_dir / 'bag' if args.duration else None
    code = 0
    try:
        for spec in specs:
            link = sim_tty_link(namespace) if spec.executable == 'fish_sim' else None
            if link is not None:
                remove_stale_link(link)
            proc = supervisor.start(spec)
            if link is not None:
                if not wait_for_path(link, [proc], DEVICE_TIMEOUT_S):
                    raise RuntimeError('the virtual fish did not open its pseudo-terminal:\n'
                                       + supervisor.log_tail(spec.name))
                print(f'virtual fish on {link} -> {link.resolve()}')
        if bag_path is not None:
            supervisor.start(NodeSpec('wirefish_bringup', 'wirefish', 'recorder', (
                'record', '-o', str(bag_path), '--namespace', namespace)))
        print(f'started {len(supervisor.processes)} processes in {namespace}; '
              f'logs in {run_dir / "logs"}')
        node_names = [spec.name for spec in specs if spec.name != 'fish_nodes']
        if args.single_process:
            node_names += list(COMPOSED_NODES)
        status = _wait_ready(namespace, node_names, not args.no_status, stop_requested)
        if status and status.startswith('not up'):
            raise RuntimeError(status)
        if status:
            print(status)
        if stop_requested:
            pass  # Ctrl-C during start-up: straight to stopping
        elif bag_path is not None:
            print(f'recording to {bag_path}; stopping after {args.duration:g} s')
        else:
            print('running: Ctrl-C stops everything')
        started = time.monotonic()
        while not stop_requested:
            exited = supervisor.exited()
            if exited:
                name, rc = next(iter(exited.items()))
                raise RuntimeError(f'{name} exited with code {rc}:\n'
                                   + supervisor.log_tail(name))
            if args.duration is not None and time.monotonic() - started >= args.duration:
                break
            time.sleep(0.1)
    except (RuntimeError, FileNotFoundError) as error:
        print(f'wirefish up: {error}', file=sys.stderr)
        code = 1
    finally:
        codes = supervisor.stop()
    unclean = {name: rc for name, rc in codes.items() if rc != 0}
    if unclean:
        print(f'wirefish up: processes that did not exit cleanly: {unclean}', file=sys.stderr)
        code = code or 1
    print(f'stopped {len(codes)} processes: '
          + ', '.join(f'{name}={rc}' for name, rc in codes.items()))
    if bag_path is not None and bag_path.exists() and code == 0:
        from wirefish_bringup.report import write_report
        report_dir = run_dir / 'report'
        write_report(bag_path, report_dir)
        print(f'bag: {bag_path}\nreport: {report_dir}')
    return code
