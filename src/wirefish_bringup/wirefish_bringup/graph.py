# SPDX-License-Identifier: Apache-2.0
"""
The wirefish node graph as data: the one registry of a fish's processes (``NODES``).

Everything that starts or checks the graph reads ``NODES``: the `wirefish up` launcher, the
single-process mode (`wirefish compose`), `launch/wirefish.launch.py`, the signal tests and the
end-to-end tests (the streams and rates below). Adding a node is one ``NodeEntry`` here plus its
package (its setup.py entry point and its YAML section).

Restart policy. A process of the graph that exits while the graph runs is
restarted after ``delay_s``; each further restart within ``window_s`` waits ``backoff`` times
longer (capped at ``max_delay_s``), so a crash loop slows down instead of spinning. The exit
after ``max_restarts`` restarts within ``window_s`` spends the budget: the launcher reports the
node as given up and keeps the rest of the graph running; if the node is ``required`` (the
graph is useless without it: the fish, or the bridge that talks to it), it stops the whole
graph with exit code 1. Either way `wirefish up` ends with a non-zero code, since the graph it
ran was not whole. `ros2 launch` honours the same policy as far as launch can express it:
``respawn``, ``respawn_delay`` (constant: launch has no back-off) and ``respawn_max_retries``
(counted over the whole run, not per window); a required node shuts the launch down once its
retries are spent.
"""

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
import enum
import math
from pathlib import Path
import re

from ament_index_python.packages import get_package_prefix, get_package_share_directory
from wirefish_common.frames import frame_prefix_problem
import yaml

DEFAULT_NAMESPACE = '/wirefish'
PARAMS_FILE_NAME = 'wirefish.yaml'
_NAMESPACE_PATTERN = re.compile(r'^(/[A-Za-z][A-Za-z0-9_]*)+$|^/$')


class When(enum.Enum):
    """When an entry is part of the graph (it never leaves the registry: a plain Enum)."""

    ALWAYS = 'always'
    SIM = 'sim'  # only with the virtual fish
    RECORD = 'record'  # only when recording
    # Only when the fish runs apart from its shore (role fish: the link relay, see crossing.py).
    APART = 'apart'
    QEMU = 'qemu'  # only with the emulated board: the firmware's ARM build in QEMU (--fish qemu)
    VIEW = 'view'  # only with the live view (`wirefish up --view`): Foxglove server, dashboard


class Role(enum.StrEnum):
    """
    Which side of the radio link an entry runs on (`wirefish up --role`, the launch argument).

    The fish side is everything that keeps the fish safe and swimming without shore; the shore
    side only tunes, records, drives. ALL: both sides on one machine.
    """

    FISH = 'fish'
    SHORE = 'shore'
    ALL = 'all'


@dataclass(frozen=True)
class RestartPolicy:
    """How the graph answers a process's exit (see the module docstring)."""

    respawn: bool = True
    delay_s: float = 1.0
    max_restarts: int = 3
    window_s: float = 60.0
    backoff: float = 2.0
    max_delay_s: float = 10.0
    required: bool = False

    def __post_init__(self) -> None:
        """Refuse a policy that cannot be honoured (a negative delay, a backoff below 1)."""
        for name in ('delay_s', 'window_s', 'max_delay_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f'restart policy: {name} must be finite and >= 0, got {value}')
        if not (math.isfinite(self.backoff) and self.backoff >= 1.0):
            raise ValueError(f'restart policy: backoff must be >= 1, got {self.backoff}')
        if self.max_restarts < 0:
            raise ValueError(f'restart policy: max_restarts must be >= 0, '
                             f'got {self.max_restarts}')

    def delay_before(self, restart_number: int) -> float:
        """Return the wait before the ``restart_number``-th restart (1-based) in the window."""
        return min(self.delay_s * self.backoff ** (restart_number - 1), self.max_delay_s)


NO_RESTART = RestartPolicy(respawn=False, max_restarts=0)


class RestartBudget:
    """
    The restarts one process has had within its policy's window (pure: times are passed in).

    ``on_exit(now)`` answers each exit: the delay before restarting, or None once the budget
    is spent (or the policy never restarts).
    """

    def __init__(self, policy: RestartPolicy) -> None:
        """Start with no restarts."""
        self.policy = policy
        self._restarts: list[float] = []
        self.total = 0

    def on_exit(self, now: float) -> float | None:
        """Return the delay before the restart this exit earns, or None: not restarted."""
        if not self.policy.respawn:
            return None
        recent = [t for t in self._restarts if now - t < self.policy.window_s]
        if len(recent) >= self.policy.max_restarts:
            return None
        self._restarts = [*recent, now]
        self.total += 1
        return self.policy.delay_before(len(self._restarts))

    @property
    def in_window(self) -> int:
        """Return how many restarts the current window holds."""
        return len(self._restarts)


@dataclass(frozen=True)
class NodeEntry:
    """
    One process of the registry.

    ``name`` is its ROS node name; ``node_class`` (``'module:Class'``, taking rclpy Node
    keyword arguments) lets the single-process mode host it, None keeps it a process of its
    own. ``arguments`` go before ``--ros-args`` and ``parameters`` are set on top of the
    parameter file; both may use ``{device}`` (the fish's serial device), ``{namespace}``,
    ``{recorded}`` (the namespace a recorder records: the shore's copies with the shore role)
    and ``{bag}``; ``ros_args`` False: the process parses its own options only (no ``--ros-args``
    section). ``start_order`` is the same whatever the role (lower first). ``creates_link``:
    the process publishes ``{device}`` as a symlink (the launcher removes a stale one before
    each start and waits for it at start-up). ``own_executor``: in one process it spins on a
    multi-threaded executor and a thread of its own (its service waits for another node's
    answer). ``rates_hz`` are its streams at their nominal rates at the default parameters,
    ``min_rates_hz`` its slow streams (at least that often); ``fed_by`` names the nodes whose
    output its streams are computed from (they may pause while one of those is down).
    ``role`` is the side of the radio link it runs on (FISH or SHORE); ``frames``: it writes
    frame ids and takes the ``frame_prefix`` parameter (a fleet's fish_1/base_link).
    """

    package: str
    executable: str
    name: str
    start_order: int
    node_class: str | None = None
    when: When = When.ALWAYS
    arguments: tuple[str, ...] = ()
    parameters: Mapping[str, str] = field(default_factory=dict)
    ros_args: bool = True
    creates_link: bool = False
    own_executor: bool = False
    restart: RestartPolicy = RestartPolicy()
    rates_hz: Mapping[str, float] = field(default_factory=dict)
    min_rates_hz: Mapping[str, float] = field(default_factory=dict)
    fed_by: tuple[str, ...] = ()
    role: Role = Role.FISH
    frames: bool = False


NODES: tuple[NodeEntry, ...] = (
    NodeEntry('wirefish_sim', 'fish_sim', 'fish_sim', start_order=0, when=When.SIM,
              arguments=('--link', '{device}', '--ros'), creates_link=True, frames=True,
              restart=RestartPolicy(required=True), rates_hz={'sim/ground_truth': 50.0}),
    # The firmware on an emulated STM32F405 (qemu_board): no physics, so no sim/ground_truth.
    NodeEntry('wirefish_launcher', 'qemu_board', 'qemu_fish', start_order=0, when=When.QEMU,
              arguments=('--link', '{device}'), creates_link=True, ros_args=False,
              restart=RestartPolicy(required=True)),
    NodeEntry('wirefish_bridge', 'bridge_node', 'bridge_node', start_order=10,
              node_class='wirefish_bridge.bridge_node:BridgeNode',
              parameters={'port': '{device}'}, restart=RestartPolicy(required=True), frames=True,
              rates_hz={'imu/data': 100.0, 'attitude': 100.0, 'servo_state': 100.0,
                        'battery': 10.0},
              min_rates_hz={'/diagnostics': 0.5}, fed_by=('fish_sim',)),
    NodeEntry('wirefish_cpg', 'cpg_node', 'cpg_node', start_order=20,
              node_class='wirefish_cpg.cpg_node:CpgNode', rates_hz={'servo_cmd': 100.0}),
    NodeEntry('wirefish_kinematics', 'kinematics_node', 'kinematics_node', start_order=30,
              node_class='wirefish_kinematics.kinematics_node:KinematicsNode', frames=True,
              rates_hz={'body_wave': 50.0, 'body_wave_markers': 10.0},
              min_rates_hz={'speed_estimate': 0.5}, fed_by=('cpg_node',)),
    # The TF tree (/tf, /tf_static): odom -> base_link, the mounts and the tail's frames.
    NodeEntry('wirefish_tf', 'tf_node', 'tf_node', start_order=32,
              node_class='wirefish_tf.tf_node:TfNode', frames=True),
    # The fish starts still: cpg_node's autostart is false (config/wirefish.yaml) and the planner
    # holds the targets at rest (rest_at_start) until the first command, when it starts the CPG.
    NodeEntry('wirefish_planner', 'planner_node', 'planner_node', start_order=35,
              node_class='wirefish_planner.planner_node:PlannerNode', fed_by=('bridge_node',)),
    NodeEntry('wirefish_tuner', 'tuner_node', 'tuner_node', start_order=40,
              node_class='wirefish_tuner.tuner_node:TunerNode', own_executor=True,
              role=Role.SHORE),
    # The fish's side of the radio: the decimated copies the shore sees (config/crossing.yaml).
    NodeEntry('wirefish_relay', 'link_relay', 'link_relay', start_order=45, when=When.APART),
    # `wirefish up --duration`. Restarted with --resume: a killed recorder's bag is reindexed
    # and the new one records on into its next split file (the run keeps one bag).
    NodeEntry('wirefish_bag', 'recorder', 'wirefish_recorder', start_order=50, when=When.RECORD,
              arguments=('-o', '{bag}', '--namespace', '{recorded}', '--resume'),
              role=Role.SHORE, ros_args=False),
    # `wirefish up --view`: the Foxglove WebSocket server over the graph and the dashboard.
    NodeEntry('wirefish_view', 'view_node', 'view_node', start_order=60, when=When.VIEW,
              role=Role.SHORE, frames=True),
)

# The process that hosts every entry with a node_class in single-process mode.
COMPOSED_NAME = 'fish_nodes'
_RELEASING_EXECUTABLES = frozenset({(e.package, e.executable) for e in NODES}
                                   | {('wirefish_launcher', 'compose')})


@dataclass(frozen=True)
class NodeSpec:
    """
    One process to start: `ros2 run <package> <executable> <arguments> [--ros-args ...]`.

    ``arguments`` come first, verbatim; when ``namespace`` is set, a ``--ros-args`` section
    follows with the node name, namespace, ``params_file`` and ``parameters``. ``ros_nodes``
    are the ROS node names the process hosts; ``links`` the device symlinks it creates (a
    fleet's one virtual-fish process: one per fish).
    """

    package: str
    executable: str
    name: str
    arguments: tuple[str, ...] = ()
    namespace: str | None = None
    params_file: str | None = None
    parameters: Mapping[str, str] = field(default_factory=dict)
    restart: RestartPolicy = NO_RESTART
    ros_nodes: tuple[str, ...] = ()
    links: tuple[Path, ...] = ()
    remaps: Mapping[str, str] = field(default_factory=dict)

    def executable_path(self) -> Path:
        """Return the installed executable, where `ros2 run` finds it (lib/<package>/)."""
        return Path(get_package_prefix(self.package), 'lib', self.package, self.executable)

    @property
    def releases_stop_signals(self) -> bool:
        """
        Whether the process unblocks SIGINT/SIGTERM once its own handler is in place.

        Every executable of the registry does (``wirefish_common.startup_signals``), so a
        launcher may start it with both blocked and lose no stop during its start-up; any other
        process would never see them.
        """
        return (self.package, self.executable) in _RELEASING_EXECUTABLES

    def command_arguments(self) -> tuple[str, ...]:
        """Return the arguments after the executable (what `ros2 run` would pass)."""
        if self.namespace is None:
            return self.arguments
        return (*self.arguments, *ros_arguments(self.name, self.namespace, self.params_file,
                                                self.parameters, self.remaps))

    def typed_parameters(self) -> dict[str, bool | int | float | str]:
        """Return ``parameters`` typed as ``-p key:=value`` reads them: for launch_ros's dict."""
        return {key: parameter_value(text) for key, text in self.parameters.items()}


def parameter_value(text: str) -> bool | int | float | str:
    """
    Return a registry value as rcl reads ``-p key:=text``: YAML (``false``: a bool).

    launch_ros writes a ``parameters`` dict into YAML as it is, so the launch file must pass
    these typed values: the string ``'false'`` would reach the node as a string.
    """
    value = yaml.safe_load(text) if text else text
    return value if isinstance(value, (bool, int, float, str)) else text


def ros_arguments(name: str, namespace: str, params_file: str | None,
                  parameters: Mapping[str, str],
                  remaps: Mapping[str, str] | None = None) -> tuple[str, ...]:
    """Return the ``--ros-args`` of one node: name, namespace, remaps, parameter file, values."""
    args = ['--ros-args', '-r', f'__node:={name}', '-r', f'__ns:={namespace}']
    for source, target in (remaps or {}).items():
        args += ['-r', f'{source}:={target}']
    if params_file is not None:
        args += ['--params-file', params_file]
    for key, value in parameters.items():
        args += ['-p', f'{key}:={value}']
    return tuple(args)


def validate_namespace(namespace: str) -> str:
    """Return ``namespace`` normalised to an absolute ROS namespace, or raise ValueError."""
    if not namespace.strip():  # '' would silently be the root namespace
        raise ValueError('an empty namespace: give one, e.g. /wirefish (or / for the root)')
    if not namespace.startswith('/'):
        namespace = '/' + namespace
    namespace = namespace.rstrip('/') or '/'
    if not _NAMESPACE_PATTERN.match(namespace):
        raise ValueError(f'invalid ROS namespace {namespace!r}: use letters, digits and _, '
                         'each token starting with a letter (e.g. /wirefish or /tank/fish_1)')
    return namespace


def default_params_file() -> Path:
    """Return the installed default parameter file of the graph."""
    return Path(get_package_share_directory('wirefish_bringup'), 'config', PARAMS_FILE_NAME)


def qemu_tty_link(namespace: str) -> Path:
    """Return the symlink path under which the emulated board publishes its USART1 pty."""
    token = validate_namespace(namespace).strip('/').replace('/', '_') or 'root'
    return Path('/tmp', f'wirefish-{token}-qemu-tty')


def sim_tty_link(namespace: str) -> Path:
    """Return the symlink path under which the virtual fish publishes its pseudo-terminal."""
    token = validate_namespace(namespace).strip('/').replace('/', '_') or 'root'
    return Path('/tmp', f'wirefish-{token}-tty')


def entries(*, sim: bool, record: bool = False, role: str = Role.ALL,
            qemu: bool = False, view: bool = False) -> list[NodeEntry]:
    """
    Return the registry entries of a graph, in start order.

    ``sim``: with the virtual fish; ``record``: with the recorder; ``role``: one side of the
    radio link (FISH, SHORE) or both on one machine (ALL). The link relay runs with the fish
    role only: with both sides on one host nothing crosses a radio. ``qemu``: with the
    emulated board (the firmware in QEMU) as the fish; ``view``: with the live view.
    """
    try:
        role = Role(role)
    except ValueError:
        raise ValueError(f'unknown role {role!r}: choose one of {", ".join(Role)}') from None
    active = {When.ALWAYS, *([When.SIM] if sim else []), *([When.QEMU] if qemu else []),
              *([When.RECORD] if record else []), *([When.VIEW] if view else []),
              *([When.APART] if role == Role.FISH else [])}
    return sorted((e for e in NODES if e.when in active and role in (Role.ALL, e.role)),
                  key=lambda e: e.start_order)


def composable_entries() -> list[NodeEntry]:
    """Return the entries the single-process mode hosts (those with a node class), in order."""
    return sorted((e for e in NODES if e.node_class is not None), key=lambda e: e.start_order)


def entry(name: str) -> NodeEntry:
    """Return the registry entry of node ``name``, or raise KeyError."""
    for candidate in NODES:
        if candidate.name == name:
            return candidate
    raise KeyError(f'no node {name!r} in the graph registry')


def resolve(template: str, **values: str) -> str:
    """Fill the ``{device}``/``{namespace}``/``{bag}`` placeholders of a registry value."""
    try:
        return template.format(**values)
    except KeyError as error:
        missing = error.args[0]
        raise ValueError(f'{template!r} needs {missing!r}, which this graph lacks') from error


def combined_policy(policies: list[RestartPolicy]) -> RestartPolicy:
    """Return the policy of one process hosting several nodes: the strictest of theirs."""
    return RestartPolicy(respawn=all(p.respawn for p in policies),
                         delay_s=max(p.delay_s for p in policies),
                         max_restarts=min(p.max_restarts for p in policies),
                         window_s=max(p.window_s for p in policies),
                         backoff=max(p.backoff for p in policies),
                         max_delay_s=max(p.max_delay_s for p in policies),
                         required=any(p.required for p in policies))


def expected_rates(*, sim: bool = True) -> tuple[dict[str, float], dict[str, float]]:
    """Return the graph's streams: ({topic: nominal Hz}, {slow topic: minimum Hz})."""
    nominal: dict[str, float] = {}
    minimum: dict[str, float] = {}
    for e in entries(sim=sim):
        nominal.update(e.rates_hz)
        minimum.update(e.min_rates_hz)
    return nominal, minimum


def fish_graph(namespace: str = DEFAULT_NAMESPACE, *, sim: bool = True,
               port: str | None = None, params_file: Path | str | None = None,
               single_process: bool = False, bag: Path | None = None, role: str = Role.ALL,
               frame_prefix: str = '', qemu: bool = False,
               view: bool = False) -> list[NodeSpec]:
    """
    Return the processes of one fish's graph, in start order (the virtual fish first).

    ``namespace`` holds every node and (relative) topic; ``sim`` starts the virtual fish and
    points the bridge at its pseudo-terminal, otherwise ``port`` names the real fish's serial
    device; ``params_file`` is the parameter YAML (the installed default when None);
    ``single_process`` runs the ROS nodes with a node class in one process (`wirefish
    compose`); ``bag`` adds the recorder, writing there; ``role`` starts one side of the radio
    link only (FISH or SHORE; ALL: both); ``frame_prefix`` goes to every node that writes frame
    ids (``fish_1``: ``fish_1/base_link``); ``qemu`` (with ``sim`` False): the fish is the
    firmware on an emulated board, the bridge on its pty; ``view`` adds the live view.
    """
    namespace = validate_namespace(namespace)
    if qemu and (sim or port):
        raise ValueError('the emulated board is the fish: no virtual fish or port with it')
    if qemu:
        port = str(qemu_tty_link(namespace))
    if not sim and not port:
        raise ValueError('a real fish needs its serial port (e.g. --port /dev/ttyUSB0)')
    if sim and port:  # e.g. `ros2 launch ... port:=/dev/ttyUSB0` without sim:=false
        raise ValueError(f'a serial port ({port}) was given for the virtual fish: '
                         'choose sim or a port (sim:=false port:=...)')
    params = str(params_file or default_params_file())
    device = str(sim_tty_link(namespace)) if sim else str(port)
    # The shore alone records what crosses the link (shore/...), never the fish's fast streams.
    recorded = f'{namespace.rstrip("/")}/shore' if role == Role.SHORE else namespace
    values = {'device': device, 'namespace': namespace, 'recorded': recorded,
              **({'bag': str(bag)} if bag else {})}
    specs: list[NodeSpec] = []
    composed: list[NodeEntry] = []
    prefix_problem = frame_prefix_problem(frame_prefix)
    if prefix_problem is not None:
        raise ValueError(prefix_problem)
    if single_process and (role != Role.ALL or frame_prefix):
        raise ValueError('the single-process mode hosts one whole fish (wirefish compose): '
                         'a role or a frame prefix needs one process per node')
    with_prefix = {'frame_prefix': frame_prefix} if frame_prefix else {}
    for e in entries(sim=sim, record=bag is not None, role=role, qemu=qemu, view=view):
        if single_process and e.node_class is not None:
            composed.append(e)
            continue
        specs.append(NodeSpec(
            e.package, e.executable, e.name,
            arguments=tuple(resolve(a, **values) for a in e.arguments),
            namespace=namespace if e.ros_args else None,
            params_file=params,
            parameters={**{k: resolve(v, **values) for k, v in e.parameters.items()},
                        **(with_prefix if e.frames else {})},
            # A process that parses its own options names its node itself (the recorder's
            # is outside the namespace): nothing to wait for or to look for there.
            restart=e.restart, ros_nodes=(e.name,) if e.ros_args else (),
            links=(Path(device),) if e.creates_link else ()))
    if composed:
        specs.append(NodeSpec(
            'wirefish_launcher', 'compose', COMPOSED_NAME,
            arguments=('--namespace', namespace, '--port', device,
                       '--params-file', params),
            restart=combined_policy([e.restart for e in composed]),
            ros_nodes=tuple(e.name for e in composed)))
        specs.sort(key=lambda s: _start_order(s, composed))
    return specs


# On the simulated-time road a step of fish_sim's clock waits for the bridge's SERVO_CMD, and
# the bridge's rate limit counts wall time: at 100 Hz a command that came a few ms early (after
# a late one) was held until the next command or command tick, both of which wait for the
# clock, so the clock waited out its grace (5 times in 20 s at --speed 1); and it would cap
# `--speed max` near real time. There the limit is the parameter's most (1 kHz: at most 10
# times real time), and the lockstep paces the commands: one per step.
SIM_TIME_COMMAND_RATE_HZ = '1000.0'


def on_simulated_time(specs: list[NodeSpec], speed: str) -> list[NodeSpec]:
    """
    Return a virtual-fish graph's processes with fish_sim owning the clock at ``speed``.

    fish_sim gets ``--speed`` (it publishes the clock and steps in lockstep with the host's
    SERVO_CMD, ``wirefish_sim.lockstep``); every other ROS node of the graph gets
    ``use_sim_time`` (the single-process host: ``--sim-time``), so its timers, stamps and
    timeouts run on simulated time. The clock is ``<fish_sim's namespace>/clock``
    (``clock_topic``), which every node takes as its /clock (a remap): two graphs on one ROS
    domain, in namespaces of their own, each keep their own time. The bridge's command rate
    limit is lifted to its most
    (``SIM_TIME_COMMAND_RATE_HZ``). ``speed`` is ``--speed``'s text (``1``,
    ``4``, ``max``). A process that parses its own options (the recorder) keeps the wall clock
    for its receive times; the messages it records carry simulated stamps.
    """
    clock = simulated_clock_of(specs)
    simulator = entry('fish_sim')
    owners = [s for s in specs
              if (s.package, s.executable) == (simulator.package, simulator.executable)]
    timed = []
    for spec in specs:
        if spec in owners:
            spec = replace(spec, arguments=(*spec.arguments, '--speed', speed))
        elif spec.name == COMPOSED_NAME:
            spec = replace(spec, arguments=(*spec.arguments, '--sim-time', '--clock', clock))
        elif spec.namespace is not None:
            spec = replace(spec, parameters={**spec.parameters,
                                             **simulated_time_parameters(spec.executable)},
                           remaps={**spec.remaps, '/clock': clock})
        timed.append(spec)
    return timed


def simulated_clock_of(specs: list[NodeSpec]) -> str:
    """Return the clock topic of a virtual-fish graph: its (first) fish_sim's ``clock_topic``."""
    simulator = entry('fish_sim')
    for spec in specs:
        if (spec.package, spec.executable) == (simulator.package, simulator.executable):
            return clock_topic(spec.namespace or '/')
    raise ValueError("simulated time is the virtual fish's clock: this graph has none")


def simulated_time_parameters(executable: str) -> dict[str, str]:
    """
    Return the parameters node ``executable`` gets on the virtual fish's clock.

    Every node: ``use_sim_time``. The bridge: its command rate limit lifted
    (``SIM_TIME_COMMAND_RATE_HZ``). The tf_node: odom -> base_link from the virtual fish's
    ground truth from the first transform; its ``auto`` would dead-reckon until the truth is
    heard, stamped on the same simulated instants as the truths, then jump to them.
    """
    extra = {'use_sim_time': 'true'}
    if executable == 'bridge_node':
        extra['max_command_rate_hz'] = SIM_TIME_COMMAND_RATE_HZ
    if executable == 'tf_node':
        extra['odom_source'] = 'ground_truth'
    return extra


def clock_topic(namespace: str) -> str:
    """Return the clock a virtual fish in ``namespace`` publishes (``<namespace>/clock``)."""
    return f'{namespace.rstrip("/")}/clock'


def _start_order(spec: NodeSpec, composed: list[NodeEntry]) -> int:
    if spec.name == COMPOSED_NAME:
        return min(e.start_order for e in composed)
    return entry(spec.name).start_order
