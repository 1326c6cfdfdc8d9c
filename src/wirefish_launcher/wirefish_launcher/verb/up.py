# SPDX-License-Identifier: Apache-2.0
"""
`wirefish up`: start one fish's whole graph, show its status, run until Ctrl-C, stop cleanly.

The launcher for machines without `ros2 launch`; `launch/wirefish.launch.py` starts the same
graph (see `wirefish_bringup.graph`) on a full install. A node that exits is restarted by its
restart policy (graph.py) while the others run on; a second `wirefish up` in a namespace whose
nodes are already discovered on this ROS domain refuses to start (--allow-duplicate overrides).
"""

import argparse
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from datetime import datetime
import enum
import importlib.util
import math
import os
from pathlib import Path
import sys
import time
from typing import Any

from wirefish_bringup.dds_profile import graph_environment, write_profile
from wirefish_bringup.graph import (DEFAULT_NAMESPACE, fish_graph, NodeSpec, Role,
                                    validate_namespace)
from wirefish_cli.api import duration_s
from wirefish_common.input_checks import params_file_problem, parse_speed, serial_port_problem
from wirefish_common.progress import duration_text, Progress
from wirefish_launcher.errors import QemuBoardError
from wirefish_launcher.radio_road import bridge_settings, DriveMode, Radio, with_radio
from wirefish_launcher.status_view import LiveStatus, SimulatedClock, TerminalBlock
from wirefish_launcher.stop_flag import stop_on_signals, StopFlag
from wirefish_launcher.supervisor import Supervisor, wait_for_path

STATUS_WINDOW_S = 3.0
LIVE_REFRESH_S = 1.0  # how often the status is redrawn on a terminal
STOP_GRACE_S = 10.0  # after a Ctrl-C during start-up, how long the nodes may take to be up
DEVICE_TIMEOUT_S = 15.0
# How long the processes may take to stop after the SIGINT, together: one fish's 6 stop well
# within 5 s; a fleet's 19 on the loaded 2 cores needed more (a kinematics_node of 3 fish was
# still stopping after 5 s), since each process needs CPU time to finish.
STOP_TIMEOUT_S = 5.0
STOP_S_PER_PROCESS = 1.0
STOP_LOG_LINES = 60  # of a process that had to be killed: enough for its threads' stacks
# Start-up may include restarts with back-off (1 + 2 + 4 s) of a node that fails at once, and
# 8 graphs started at once on the 2-core reference machine (56 processes importing rclpy and
# numpy together, load average ~120) had the last graph's nodes discovered 60-80 s on.
READY_TIMEOUT_S = 120.0
# While it waits longer than this, `wirefish up` says how far start-up has got, every as long.
READY_PROGRESS_S = 15.0
# How long a new `wirefish up` listens for the registry's nodes already in its namespace (it
# answers at once when one is found). Discovery of a running node on one host took 0 to 2.3 s
# on the loaded 2-core machine (6 tries): twice that leaves a margin.
DUPLICATE_CHECK_S = 4.0
# A timed run on simulated time ends after --duration of the virtual fish's clock; a clock that
# has not moved for this long (wall s: the virtual fish gone, its restarts given up) ends it.
CLOCK_STALL_S = 30.0
# A timed run on simulated time counts from when the recorder takes the virtual fish's clock:
# counted from the recording line, a recorder that discovered the fish late (a loaded machine:
# 0.3 simulated s at --speed 0.5) got less than --duration into its bag. At most this long
# (wall s) is waited for it.
RECORDER_WAIT_S = 30.0


class Fish(enum.StrEnum):
    """What `wirefish up --fish` drives: the virtual fish or the firmware on an emulated board."""

    SIM = 'sim'
    QEMU = 'qemu'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish up`."""
    target = parser.add_mutually_exclusive_group()
    target.add_argument('--sim', action='store_true', default=True,
                        help='drive the virtual fish on a pseudo-terminal (default)')
    target.add_argument('--port', help='serial device of a real fish, e.g. /dev/ttyUSB0')
    target.add_argument('--fish', choices=[fish.value for fish in Fish], default=None,
                        help='sim: the virtual fish (as --sim); qemu: the firmware on an '
                        'emulated STM32F405 (QEMU; built with make -C firmware qemu), the bridge '
                        'on its pty (no physics: no sim/ground_truth)')
    parser.add_argument('--speed', type=speed_option, default=None, metavar='X',
                        help='the virtual fish owns the clock: every node on simulated time '
                        "(/clock, use_sim_time), stepped in lockstep with the CPG's commands "
                        'at X times real time: 1 (default) is real time when the machine keeps '
                        'up, max as fast as the graph answers; the live status shows the '
                        'real-time factor. Only with the virtual fish on one host: a real '
                        'fish, the emulated board and a radio run on the wall clock')
    parser.add_argument('--radio', choices=[radio.value for radio in Radio], default=None,
                        help='a radio model between the bridge and the virtual fish or the '
                        'emulated board (wired, bluetooth, rf433: docs/REFERENCE.md gives their '
                        'numbers); the radio runs on the wall clock, so the virtual fish does '
                        'too (no --speed). Its counters go to <run>/radio.json, what the fish '
                        'sends before the radio to <run>/radio-fish.tap; "cut SECONDS" '
                        'written to <run>/radio-control cuts it')
    parser.add_argument('--drive-mode', choices=[mode.value for mode in DriveMode],
                        default=None,
                        help="bridge_node's drive_mode: stream forwards servo_cmd, gait sends "
                        'the CPG parameters and the board integrates eq 1 (default: stream '
                        "with --sim and --fish qemu, gait with --port, the preset's with "
                        '--radio: gait on bluetooth and rf433)')
    parser.add_argument('--namespace', default=DEFAULT_NAMESPACE,
                        help='ROS namespace (of a fleet: its base, fish in <ns>/fish_<i>)')
    parser.add_argument('--role', choices=[role.value for role in Role],
                        default=Role.ALL.value,
                        help='one side of a radio link: fish (virtual fish or port, bridge, '
                        'CPG, kinematics, planner, link relay) or shore (tuner, recorder); '
                        'all: both on this machine (default). See README: two hosts')
    parser.add_argument('--fleet', type=fleet_size, default=None, metavar='N',
                        help='N virtual fish, each its whole graph in <namespace>/fish_<i> with '
                        'frames fish_<i>/...; one recorder of them all with --duration')
    parser.add_argument('--frame-prefix', default='',
                        help='prefix of the frame ids (fish_1 -> fish_1/base_link)')
    parser.add_argument('--duration', type=duration_s, default=None,
                        help='run this many seconds (of simulated time on the virtual fish), '
                        'record a bag and write a report')
    parser.add_argument('--params-file', type=Path, default=None,
                        help='parameter YAML (default: the installed config/wirefish.yaml)')
    parser.add_argument('--out', type=Path, default=Path('out'),
                        help='where run logs, bags and reports go (default: ./out)')
    parser.add_argument('--single-process', action='store_true',
                        help="run the fish's ROS nodes in one process (wirefish compose)")
    parser.add_argument('--no-status', action='store_true',
                        help='no status (topic rates, link, battery, planner mode; on a '
                        'terminal kept up to date while the graph runs)')
    parser.add_argument('--view', action='store_true',
                        help='also the live view: Foxglove WebSocket server and dashboard '
                        '(wirefish view; view_node parameters port, http_port)')
    parser.add_argument('--start-swimming', action='store_true',
                        help="swim the parameter file's gait from start-up (default: the fish "
                        'starts still, the servos at neutral until the first cmd_vel that '
                        'asks to move or retune applied)')
    parser.add_argument('--view-port', type=port_number, default=None, metavar='PORT',
                        help="with --view: the Foxglove WebSocket port (view_node's port, "
                        'default 8765; 0: any free one)')
    parser.add_argument('--view-http-port', type=port_number, default=None, metavar='PORT',
                        help="with --view: the dashboard's HTTP port (view_node's http_port, "
                        'default 8080; 0: any free one)')
    parser.add_argument('--baud', type=int, default=None,
                        help="the serial link's baud rate (bridge_node's baudrate, default "
                        '115200)')
    parser.add_argument('--allow-duplicate', action='store_true',
                        help='start even if nodes of the graph already run in this namespace '
                        '(e.g. a graph that just died is still discovered)')


def with_calibration_files(specs: list[NodeSpec], directory: Path) -> list[NodeSpec]:
    """
    Return ``specs`` with each fish_sim given a calibration file per fish under ``directory``.

    The virtual fish keeps its servo calibration record log there (``--calibration``): a
    fish_sim that the supervisor restarts boots with what was saved, as a board does.
    """
    out = []
    for spec in specs:
        if (spec.package, spec.executable) == ('wirefish_sim', 'fish_sim'):
            count = max(spec.arguments.count('--link'), 1)
            extra = [arg for k in range(count) for arg in
                     ('--calibration', str(directory / f'{spec.name}-calibration-{k + 1}.bin'))]
            spec = replace(spec, arguments=(*spec.arguments, *extra))
        out.append(spec)
    return out


def port_number(text: str) -> int:
    """Return a TCP port option: a whole number in 0..65535, 0 any free one (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a port number: {text!r}') from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f'a port is 0..65535 (0: any free one), got {value}')
    return value


def speed_option(text: str) -> str:
    """Return a --speed option as given (``1``, ``4``, ``max``) once it is valid (argparse)."""
    try:
        parse_speed(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return text.strip().lower()


# The pace of the simulated-time road when `wirefish up --sim` is given no --speed: real time, so
# what a user watches, drives or records keeps the pace of the world; a loaded machine slows
# it down instead of changing it (`max` is for experiments: wirefish sweep, the benchmarks).
DEFAULT_SPEED = '1'


def on_simulated_time_road(args: argparse.Namespace) -> bool:
    """Return whether the graph runs on the virtual fish's clock: the virtual fish, one host."""
    return (args.port is None and args.fish != Fish.QEMU and args.role == Role.ALL
            and args.radio is None)   # a radio's timing is the wall clock's


def fleet_size(text: str) -> int:
    """Return a --fleet option: a whole number of fish >= 1 (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a whole number of fish: {text!r}') from None
    if value < 1:
        raise argparse.ArgumentTypeError(f'a fleet has at least 1 fish, got {value}')
    return value


def _node_names(spec: NodeSpec, namespace: str) -> list[str]:
    """Return the fully qualified names of the nodes ``spec`` hosts (a fleet's: per fish)."""
    return [f'{(spec.namespace or namespace).rstrip("/")}/{name}' for name in spec.ros_nodes]


def _registry_nodes(specs: list[NodeSpec], namespace: str) -> list[str]:
    """Return the graph's node names relative to ``namespace`` (fish_1/cpg_node in a fleet)."""
    prefix = namespace.rstrip('/') + '/'
    return [name[len(prefix):] for spec in specs for name in _node_names(spec, namespace)]


def _wait_ready(node, executor, namespace: str, specs: list[NodeSpec], supervisor: Supervisor,
                show_status: bool, stop: StopFlag,
                timeout_s: float = READY_TIMEOUT_S, role: str = Role.ALL
                ) -> tuple[str | None, LiveStatus | None]:
    """
    Wait until every node of the graph is on the ROS graph; return (status table, its status).

    A node is "up" once it is discoverable (its rclpy.init and constructor are done), so a
    Ctrl-C after "running:" always reaches nodes that handle it cleanly. Exits while waiting
    are answered by the restart policies; a node given up on is no longer waited for. The
    table is None after a stop request, '' without ``show_status``; the status that measured
    it comes with it (the live view goes on with it), None when there is no table.
    """
    from wirefish_launcher.monitor import discovered_nodes, settle_discovery

    def expected() -> set[str]:
        return {name for key, spec in supervisor.specs.items() if key not in supervisor.given_up
                for name in _node_names(spec, namespace)}

    def up() -> bool:  # discovered, and no process down (a node dying at start-up is seen)
        return expected() <= discovered_nodes(node) and not supervisor.down()

    started = time.monotonic()
    deadline = started + timeout_s
    next_progress = started + READY_PROGRESS_S
    while not up():
        _report(supervisor.supervise())
        if time.monotonic() > next_progress and not stop.requested:
            waiting = sorted(expected() - discovered_nodes(node))
            _report([f'{len(expected()) - len(waiting)} of {len(expected())} nodes up after '
                     f'{time.monotonic() - started:.0f} s (load average '
                     f'{os.getloadavg()[0]:.1f}); waiting for {", ".join(waiting)}'])
            next_progress += READY_PROGRESS_S
        if stop.requested and deadline > time.monotonic() + STOP_GRACE_S:
            # A node interrupted while still importing dies of the SIGINT (exit -2, a
            # KeyboardInterrupt trace): let every node finish starting, then stop them all.
            print('wirefish up: stopping as soon as every node has started', file=sys.stderr)
            deadline = time.monotonic() + STOP_GRACE_S
        if time.monotonic() > deadline:
            missing = ', '.join(sorted(expected() - discovered_nodes(node)))
            return (None if stop.requested else f'not up after {timeout_s:g} s: {missing}',
                    None)
        executor.spin_once(timeout_sec=0.1)
    if stop.requested:
        return None, None
    if not show_status:
        return '', None
    settle_discovery(node, executor, namespace, should_stop=lambda: stop.requested)
    # The shore watches what crosses the link only: measuring the fish's own streams would
    # pull them over the radio.
    watched = f'{namespace.rstrip("/")}/shore' if role == Role.SHORE else namespace
    live = LiveStatus(node, watched)
    measured_until = time.monotonic() + STATUS_WINDOW_S
    while time.monotonic() < measured_until and not stop.requested:
        time.sleep(0.25)
        live.refresh()
    if stop.requested:  # Ctrl-C while the table was measured: stop now, no table
        return None, None
    return '\n'.join([f'nodes: {", ".join(sorted(expected()))}', *live.lines()]), live


def _effective_params(args: argparse.Namespace, run_dir: Path
                      ) -> tuple[Path, dict, dict]:
    """
    Return the run's parameter file: the defaults, the user's file and the options on top.

    Returns (its path, the user's file as read, the merged content): ``_write_params`` writes
    it once the inputs are judged. The user's file overrides
    only what it names (``params_overlay``); the options --start-swimming, --view-port,
    --view-http-port and --baud are values on top of both.
    """
    import yaml
    from wirefish_bringup.graph import default_params_file
    from wirefish_launcher.params_overlay import overlaid

    defaults = yaml.safe_load(default_params_file().read_text(encoding='utf-8'))
    user = (yaml.safe_load(args.params_file.read_text(encoding='utf-8'))
            if args.params_file is not None else {})
    options: dict[str, dict] = {}

    def put(key: str, name: str, value: object) -> None:
        options.setdefault(key, {'ros__parameters': {}})['ros__parameters'][name] = value

    if args.start_swimming:  # Table 1's gait (the defaults file starts with amplitudes 0)
        from wirefish_cpg.cpg_node_parameters import flat_values
        from wirefish_cpg.oscillator import CpgParameters

        table1 = flat_values(CpgParameters())
        put('/**/cpg_node', 'autostart', True)
        put('/**/cpg_node', 'amplitude_1', table1['amplitude_1'])
        put('/**/cpg_node', 'amplitude_2', table1['amplitude_2'])
        put('/**/planner_node', 'rest_at_start', False)
    if args.view_port is not None:
        put('/**/view_node', 'port', args.view_port)
    if args.view_http_port is not None:
        put('/**/view_node', 'http_port', args.view_http_port)
    if args.baud is not None:
        put('/**/bridge_node', 'baudrate', args.baud)
    # The road's drive mode (radio_road), unless the user's file or --drive-mode chose one.
    chose = args.drive_mode is not None or 'drive_mode:' in yaml.safe_dump(user)
    for name, value in bridge_settings(port=args.port is not None,
                                       radio=Radio(args.radio) if args.radio else None,
                                       drive_mode=DriveMode(args.drive_mode)
                                       if args.drive_mode else None).items():
        if name != 'drive_mode' or args.drive_mode is not None or not chose:
            put('/**/bridge_node', name, value)
    if on_simulated_time_road(args):  # see graph.SIM_TIME_COMMAND_RATE_HZ; a -p loses to the
        # file's /**/bridge_node section, so the value goes here
        from wirefish_bringup.graph import SIM_TIME_COMMAND_RATE_HZ
        put('/**/bridge_node', 'max_command_rate_hz', float(SIM_TIME_COMMAND_RATE_HZ))
    merged = overlaid(overlaid(defaults, user), options)
    return run_dir / 'params.yaml', user, merged


def _write_params(path: Path, merged: dict) -> None:
    """Write the run's parameter file (once every input is judged: bad input writes nothing)."""
    import yaml

    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('# wirefish up: the installed defaults, --params-file and the options on '
                    'top\n' + yaml.safe_dump(merged, sort_keys=False), encoding='utf-8')


def _view_ports_problem(params: dict, namespace: str) -> str | None:
    """Return why the live view's ports cannot be bound on this machine (in use), or None."""
    import socket
    from wirefish_launcher.params_overlay import matched_nodes

    values: dict[str, Any] = {'port': 8765, 'http_port': 8080, 'address': '127.0.0.1'}
    view_node = f'{namespace.rstrip("/")}/view_node'
    for key, block in params.items():  # later keys of the file win, as rcl reads them
        if matched_nodes(key, [view_node]):
            values.update((k, v) for k, v in block['ros__parameters'].items() if k in values)
    taken: list[tuple[str, str]] = []  # (address:port, the option that changes it)
    why = ''
    for name, flag in (('port', '--view-port'), ('http_port', '--view-http-port')):
        if int(values[name]) <= 0:  # 0: any free port; -1: no dashboard
            continue
        with socket.socket() as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind((str(values['address']), int(values[name])))
            except OSError as error:
                taken.append((f'{values["address"]}:{values[name]}', flag))
                why = error.strerror or str(error)
    if not taken:
        return None
    return (f'the live view cannot bind {" and ".join(where for where, _ in taken)} ({why}; '
            'another `wirefish view` or `wirefish up --view`?): give '
            f'{" and ".join(flag for _, flag in taken)} '
            f'{"another port" if len(taken) == 1 else "other ports"} (0: any free one)')


def _report(lines: list[str]) -> None:
    for line in lines:
        print(f'wirefish up: {line}', file=sys.stderr, flush=True)


_PROBES: list = []  # the launcher's own nodes on the graph: never torn down (_graph_probe)


@contextmanager
def _graph_probe(namespace: str) -> Iterator[tuple]:
    """
    Yield (node, executor) of the launcher's own look at the ROS graph; never destroyed.

    Destroying a node is DDS work that can block the calling thread for good: eight graphs
    starting at once left `wirefish up` in ``Node.destroy_node`` -> ``Publisher.destroy`` of
    this probe (py-spy), its SIGINT and SIGTERM caught and never acted on, nothing stopped. So
    the launcher makes no DDS call on its way out: the probe lives as long as the process, and
    ``run`` leaves through ``os._exit`` once everything it started is stopped and reported
    (the operating system closes the probe's sockets and shared memory).
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node('wirefish_status', namespace=namespace)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    _PROBES.append((node, executor))
    yield node, executor


def _recorder_takes(node, topic: str, stop) -> bool:
    """Wait until the recorder subscribes to ``topic`` (it found its publisher); True if so."""
    from wirefish_bringup.graph import entry

    recorder = entry('wirefish_recorder').name
    deadline = time.monotonic() + RECORDER_WAIT_S
    while not stop.requested and time.monotonic() < deadline:
        if any(info.node_name == recorder
               for info in node.get_subscriptions_info_by_topic(topic)):
            return True
        time.sleep(0.05)
    return False


def run(args: argparse.Namespace) -> int:
    """Run `wirefish up`; return its exit code, or exit with it if the graph was probed."""
    code = _run(args)
    if _PROBES:  # no DDS teardown on the way out (see _graph_probe)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


class _RunTime:
    """How long a run has run: the wall clock, or the virtual fish's clock when one is given."""

    def __init__(self, clock: SimulatedClock | None) -> None:
        self._clock = clock
        self._started = time.monotonic()
        self.unit = 'simulated seconds' if clock is not None else 'seconds'
        if clock is not None:
            clock.refresh()
            self._base = clock.advanced

    def elapsed(self) -> float:
        """Return the seconds run since construction (of simulated time on a clock)."""
        if self._clock is None:
            return time.monotonic() - self._started
        self._clock.refresh()
        return self._clock.advanced - self._base

    def stalled(self) -> bool:
        """Return whether the virtual fish's clock has stood still for ``CLOCK_STALL_S``."""
        return (self._clock is not None
                and time.monotonic() - max(self._clock.moved_at, self._started) > CLOCK_STALL_S)


def _run(args: argparse.Namespace) -> int:
    stamp = datetime.now().strftime('%Y%m%d_%H%M%S')
    run_dir = (args.out / f'run_{stamp}').resolve()
    bag_path = run_dir / 'bag' if args.duration else None
    if args.params_file is not None:
        problem = params_file_problem(args.params_file)
        if problem is not None:
            print(f'wirefish up: {problem}', file=sys.stderr)
            return 2
    params_file, user_params, merged_params = _effective_params(args, run_dir)
    try:
        if bag_path is not None and importlib.util.find_spec('wirefish_bag') is None:
            # A fish install has no bag library (the fish records nothing: the shore does).
            raise ValueError('--duration records the run, which needs the wirefish_bag package '
                             '(a shore install); this host has none')
        namespace = validate_namespace(args.namespace)
        qemu = args.fish == Fish.QEMU
        sim = args.port is None and not qemu
        if args.fleet is not None:
            if args.radio is not None:
                raise ValueError('--radio puts one radio in front of one fish: not with --fleet')
            if args.port is not None or qemu or args.single_process or args.frame_prefix:
                raise ValueError('--fleet starts virtual fish, one process per node, each '
                                 'with frames fish_<i>/...: no --port, --single-process or '
                                 '--frame-prefix with it')
            from wirefish_bringup.fleet import fleet_graph
            specs = fleet_graph(namespace, args.fleet, params_file=params_file,
                                bag=bag_path, role=args.role)
        else:
            specs = fish_graph(namespace, sim=sim, port=args.port,
                               params_file=params_file, single_process=args.single_process,
                               bag=bag_path, role=args.role, frame_prefix=args.frame_prefix,
                               qemu=qemu, view=args.view)
            if qemu:
                from wirefish_launcher.qemu_board import build_image
                build_image()
            if args.radio is not None:
                specs = with_radio(specs, Radio(args.radio), stats=run_dir / 'radio.json',
                                   control=run_dir / 'radio-control',
                                   tap=run_dir / 'radio-fish.tap')
        # Each virtual fish's servo calibration outlives a restart of fish_sim within the run.
        specs = with_calibration_files(specs, run_dir / 'logs')
        clock_topic = None
        if on_simulated_time_road(args):
            from wirefish_bringup.graph import on_simulated_time, simulated_clock_of
            specs = on_simulated_time(specs, args.speed or DEFAULT_SPEED)
            clock_topic = simulated_clock_of(specs)
        elif args.speed is not None:
            raise ValueError("--speed sets the virtual fish's simulated time: a real fish "
                             '(--port), the emulated board (--fish qemu), two hosts (--role) '
                             'and a radio (--radio) run on the wall clock')
    except ValueError as error:
        print(f'wirefish up: {error}', file=sys.stderr)
        return 2
    except QemuBoardError as error:
        print(f'wirefish up: {error}', file=sys.stderr)
        return 1
    problem = ((serial_port_problem(args.port) if args.port is not None else None)
               or (_view_ports_problem(merged_params, namespace) if args.view else None))
    if problem is not None:
        print(f'wirefish up: {problem}', file=sys.stderr)
        return 2
    from wirefish_launcher.params_overlay import unused_entries
    for warning in unused_entries(user_params, [name for spec in specs
                                                for name in _node_names(spec, namespace)]):
        print(f'wirefish up: warning: --params-file {args.params_file}: {warning}',
              file=sys.stderr)
    if args.port is not None and not Path(args.port).exists():
        print(f'wirefish up: {args.port} does not exist (yet): the bridge keeps retrying until '
              'it appears; /diagnostics and its log say why it cannot open it', file=sys.stderr)
    # The reply writers' profile must name the graph's own namespaces (dds_profile).
    env, own_profile = graph_environment(
        os.environ, {s.namespace for s in specs if s.namespace}, run_dir,
        radio=args.role != Role.ALL)
    supervisor = Supervisor(run_dir / 'logs', env=env)
    stop = stop_on_signals()
    code = 0
    codes: dict[str, int | None] = {}
    run_clock = None  # --duration on simulated time counts the virtual fish's seconds
    try:
        with _graph_probe(namespace) as (node, executor):
            if not args.allow_duplicate:
                from wirefish_launcher.monitor import registry_nodes_present
                present = registry_nodes_present(node, executor, namespace,
                                                 _registry_nodes(specs, namespace),
                                                 DUPLICATE_CHECK_S,
                                                 should_stop=lambda: stop.requested)
                if present:
                    domain = os.environ.get('ROS_DOMAIN_ID', '0')
                    print(f'wirefish up: namespace {namespace} is in use on ROS domain {domain} '
                          f'({", ".join(present)} already running there): stop that graph, '
                          'choose another --namespace, or pass --allow-duplicate',
                          file=sys.stderr)
                    return 1
                if stop.requested:
                    return 0
            if clock_topic is not None and args.duration is not None:
                run_clock = SimulatedClock(node, clock_topic)
            write_profile(env, own_profile)
            _write_params(params_file, merged_params)  # nothing written before this point
            for spec in specs:
                proc = supervisor.start(spec)
                for link in spec.links:
                    if not wait_for_path(link, [proc], DEVICE_TIMEOUT_S):
                        raise RuntimeError(f'{spec.name} did not open its pseudo-terminal:\n'
                                           + supervisor.log_tail(spec.name))
                    fish = 'emulated board' if qemu else 'virtual fish'
                    print(f'{fish} on {link} -> {link.resolve()}')
            print(f'started {len(supervisor.processes)} processes in {namespace}; '
                  f'logs in {run_dir / "logs"}', flush=True)
            if any('tuner_node' in spec.ros_nodes for spec in specs):
                from wirefish_cpg.gait_library import tuner_library_path
                library = tuner_library_path(params_file)
                print(f'gait library: {library}', flush=True)
            status, measured = _wait_ready(node, executor, namespace, specs, supervisor,
                                           not args.no_status, stop, role=args.role)
            if run_clock is not None and bag_path is not None and clock_topic is not None \
                    and not _recorder_takes(node, clock_topic, stop):
                print(f'wirefish up: the recorder did not subscribe to {clock_topic} within '
                      f'{RECORDER_WAIT_S:g} s; the run counts from now', file=sys.stderr)
        if status and status.startswith('not up'):
            raise RuntimeError(status)
        # On a terminal the status is redrawn in place while the graph runs; else shown once.
        live = measured if sys.stdout.isatty() else None
        if live is None and measured is not None:
            measured.close()  # shown once: no more samples to keep
        block = TerminalBlock(sys.stdout) if live is not None else None
        if status and block is None:
            print(status)
        if stop.requested:
            pass  # Ctrl-C during start-up: straight to stopping
        elif bag_path is not None:
            print(f'recording to {bag_path}; stopping after {args.duration:g} s'
                  + (' of simulated time' if run_clock is not None else ''))
        else:
            print('running: Ctrl-C stops everything', flush=True)
        if not stop.requested and not args.start_swimming and args.role != Role.SHORE:
            print('the fish starts still (servos at neutral): `wirefish drive`, a '
                  '`wirefish retune --apply` or the dashboard set it swimming '
                  '(--start-swimming: at once)', flush=True)
        started = drawn = time.monotonic()
        run_time = _RunTime(run_clock)
        # A timed run off a terminal says how far it is (a line per 5 %, with the time left);
        # on a terminal the live status's first line says it.
        timed = (Progress('recording, ' + run_time.unit, math.ceil(args.duration),
                          stream=sys.stdout)
                 if args.duration is not None and block is None and not stop.requested
                 else None)
        while not stop.requested:
            reports = supervisor.supervise()
            if reports and block is not None:
                block.forget()  # the reports stay; the status goes on below them
            _report(reports)
            elapsed = run_time.elapsed()
            if args.duration is not None and elapsed >= args.duration:
                break
            if run_time.stalled():
                raise RuntimeError(f"the virtual fish's clock has not moved for "
                                   f'{CLOCK_STALL_S:g} s: the run stops ({elapsed:.1f} of '
                                   f'{args.duration:g} simulated s); see logs/fish_sim.log')
            if timed is not None and int(elapsed) > timed.done:
                timed.step(int(elapsed))
            if live is not None and block is not None and (
                    time.monotonic() - drawn >= LIVE_REFRESH_S or drawn == started):
                live.refresh()
                first = (status or '').splitlines()[:1]
                if args.duration is not None:
                    left = duration_text(args.duration - elapsed)
                    first = [f'{first[0] if first else "running"}; stopping in {left}']
                block.draw([*first, *live.lines()])
                drawn = time.monotonic()
            time.sleep(0.1)
    except (RuntimeError, FileNotFoundError) as error:
        print(f'wirefish up: {error}', file=sys.stderr)
        code = 1
    finally:
        stop_timeout_s = max(STOP_TIMEOUT_S, STOP_S_PER_PROCESS * len(supervisor.processes))
        codes = supervisor.stop(timeout_s=stop_timeout_s)
    summary = supervisor.summary()
    if summary:
        print(f'wirefish up: {summary}', file=sys.stderr)
    for name in supervisor.overran:  # its log ends with its threads' stacks (SignalShutdown)
        end = ('was killed' if codes[name] is None
               else f'exited with code {codes[name]} after a SIGTERM')
        print(f'wirefish up: {name} still ran {stop_timeout_s:g} s after the SIGINT and {end}; '
              f'the end of its log:\n'
              f'{supervisor.log_tail(name, lines=STOP_LOG_LINES) or "(empty)"}',
              file=sys.stderr)
    unclean = {name: rc for name, rc in codes.items() if rc != 0}
    if unclean:
        print(f'wirefish up: processes that did not exit cleanly: {unclean}', file=sys.stderr)
        code = code or 1
    print(f'stopped {len(codes)} processes: '
          + ', '.join(f'{name}={rc}' for name, rc in codes.items()))
    if bag_path is not None and bag_path.exists():
        from wirefish_bag.run_bag import close_run_bag
        close_run_bag(bag_path, run_dir / 'report' if code == 0 else None)
    return code
