# SPDX-License-Identifier: Apache-2.0
"""
Fixtures of the planner's cross-process tests: one graph per module, a driver probe in-process.

The graph is the virtual fish (with a constant yaw disturbance: a current), the bridge, the
CPG and the planner, each its own process as `wirefish up` starts them, on a domain and a
namespace of this module's own. The probe publishes cmd_vel at 20 Hz and records
sim/ground_truth, servo_cmd and planner_state with their receive times.
"""

from collections.abc import Iterator
from dataclasses import dataclass, field
import os
from pathlib import Path
import subprocess
import threading
import time

from ament_index_python.packages import get_package_prefix, get_package_share_directory
import pytest
from ros_utils import domain_context, stop_process
from wirefish_common.executors import ExecutorKind, make_executor, spin_until_stopped, wake

NAMESPACE = '/h181_planner'
YAW_DISTURBANCE_RAD_S = 0.05  # the current: 2.9 deg/s of yaw on a straight tail
CMD_RATE_HZ = 20.0
# How long (wall s) the driver waits on discovery: for the bridge to say its fish hears it
# (the graph's clock found), for a node's parameter service.
FISH_DRIVEN_WAIT_S = 60.0


def executable(package: str, name: str) -> str:
    """Return the installed executable ``name`` of ``package`` (where `ros2 run` finds it)."""
    return str(Path(get_package_prefix(package), 'lib', package, name))


@dataclass
class PlannerGraph:
    """The graph's processes and how to reach it."""

    processes: dict[str, subprocess.Popen]
    env: dict[str, str]
    domain_id: int
    namespace: str
    link: Path
    simulated: bool = False  # on fish_sim's clock (<namespace>/clock), as `wirefish up --sim`


def _default_params() -> Path:
    return Path(get_package_share_directory('wirefish_bringup'), 'config', 'wirefish.yaml')


def _ros_args(namespace: str, *extra: str, params: Path | None = None) -> list[str]:
    return ['--ros-args', '-r', f'__ns:={namespace}', '--params-file',
            str(params or _default_params()), *extra]


def _simulated_params(directory: Path) -> Path:
    """Return the graph's parameters with what `wirefish up` sets on simulated time."""
    import yaml
    from wirefish_bringup.graph import SIM_TIME_COMMAND_RATE_HZ

    values = yaml.safe_load(_default_params().read_text())
    values['/**/bridge_node']['ros__parameters']['max_command_rate_hz'] = float(
        SIM_TIME_COMMAND_RATE_HZ)
    path = directory / 'wirefish_simulated.yaml'
    path.write_text(yaml.safe_dump(values))
    return path


def start_planner_graph(domain_id: int, namespace: str = NAMESPACE,
                        fish_flags: tuple[str, ...] = (), speed: str | None = None,
                        directory: Path | None = None) -> PlannerGraph:
    """
    Start fish_sim, bridge_node, cpg_node and planner_node; return once the fish is up.

    ``speed``: on the virtual fish's clock at that pace (fish_sim --speed, every node on
    ``<namespace>/clock`` with use_sim_time, as `wirefish up --sim` starts them); the run's
    parameter file goes to ``directory``. None: the wall clock.
    """
    if speed is not None:
        from wirefish_bringup.graph import clock_topic
        assert directory is not None, 'a graph on simulated time needs a directory'
        params = _simulated_params(directory)
        timed = ('-p', 'use_sim_time:=true', '-r', f'/clock:={clock_topic(namespace)}')
        fish_flags = (*fish_flags, '--speed', speed)
    else:
        params, timed = None, ()
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1',
               RCUTILS_COLORIZED_OUTPUT='0')
    link = Path('/tmp', f'wirefish-h8-planner-{domain_id}-tty')
    procs: dict[str, subprocess.Popen] = {}

    def start(name: str, args: list[str]) -> subprocess.Popen:
        procs[name] = subprocess.Popen(args, env=env, stdout=subprocess.PIPE,
                                       stderr=subprocess.STDOUT, text=True,
                                       start_new_session=True)
        return procs[name]

    fish = start('fish_sim', [executable('wirefish_sim', 'fish_sim'), '--link', str(link),
                              '--ros', *fish_flags, *_ros_args(namespace, params=params)])
    if not fish.stdout.readline():
        raise RuntimeError('fish_sim did not start: ' + fish.stdout.read())
    start('bridge_node', [executable('wirefish_bridge', 'bridge_node'),
                          *_ros_args(namespace, '-p', f'port:={link}', *timed, params=params)])
    start('cpg_node', [executable('wirefish_cpg', 'cpg_node'),
                       *_ros_args(namespace, *timed, params=params)])
    start('planner_node', [executable('wirefish_planner', 'planner_node'),
                           *_ros_args(namespace, *timed, params=params)])
    return PlannerGraph(procs, env, domain_id, namespace, link, simulated=speed is not None)


def stop_planner_graph(graph: PlannerGraph) -> dict[str, int | None]:
    """Stop every process (SIGINT, then SIGKILL); return the exit codes, printing the logs."""
    codes = {}
    for name, proc in reversed(list(graph.processes.items())):
        codes[name] = stop_process(proc, timeout_s=10.0)
        output = proc.stdout.read()
        proc.stdout.close()
        print(f'--- {name} (exit {codes[name]}) ---\n{output[-3000:]}')
    return codes


@dataclass
class Recording:
    """What the probe heard: lists of tuples, appended from the probe's thread."""

    truth: list = field(default_factory=list)  # (t, x, y, yaw, speed, yaw_rate)
    servo: list = field(default_factory=list)  # (stamp s, p1, p2, v1, v2)
    state: list = field(default_factory=list)  # (t, PlannerState)
    diagnostics: list = field(default_factory=list)  # (t, DiagnosticStatus) of the planner
    bridge: dict = field(default_factory=dict)  # the bridge's last /diagnostics values


class Driver:
    """A node in the test process: publishes cmd_vel at 20 Hz, records the graph."""

    def __init__(self, context, namespace: str, simulated: bool = False) -> None:
        """
        Create the node, its subscriptions and the cmd_vel sender; spin on a thread.

        ``simulated``: the probe's clock is the graph's simulated time (``now``, ``sleep``
        and the 20 Hz of cmd_vel are simulated seconds), else the wall clock.
        """
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        import rclpy
        from rclpy.qos import qos_profile_sensor_data
        from sensor_msgs.msg import JointState
        from wirefish_msgs.msg import PlannerState

        self._twist = Twist
        from rclpy.parameter import Parameter
        from wirefish_bringup.graph import clock_topic
        from wirefish_common.clock_hold import ClockHold

        self.simulated = simulated
        timed = {'cli_args': ['--ros-args', '-r', f'/clock:={clock_topic(namespace)}'],
                 'parameter_overrides': [Parameter('use_sim_time', value=True)]
                 } if simulated else {}
        self.node = rclpy.create_node('h8_driver', namespace=namespace, context=context,
                                      **timed)
        self.recording = Recording()
        self.command: tuple[float, float] | None = None  # None: publish nothing
        self._lock = threading.Lock()
        self._pub = self.node.create_publisher(Twist, 'cmd_vel', 10)
        self._hold = ClockHold(self.node)  # says nothing off simulated time
        self.node.create_subscription(Odometry, 'sim/ground_truth', self._on_truth, 50)
        self.node.create_subscription(JointState, 'servo_cmd', self._on_servo,
                                      qos_profile_sensor_data)
        self.node.create_subscription(PlannerState, 'planner_state', self._on_state, 50)
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self._on_diagnostics, 50)
        self._stopping = False
        # The events executor: a Python executor's wake-ups cost ~0.2 ms each, and at ~190
        # messages a second a loaded machine left this probe behind for most of a second.
        self._executor = make_executor(ExecutorKind.EVENTS, context)
        self._executor.add_node(self.node)
        self._spinner = threading.Thread(
            target=spin_until_stopped, args=(self._executor, lambda: self._stopping),
            daemon=True)
        self._spinner.start()
        # cmd_vel from a thread of its own, not a timer among ~190 callbacks a second: a
        # probe behind on its recording must not starve the planner of cmd_vel (it rests the
        # fish after cmd_vel_timeout_s and then latches a new heading).
        self._sender = threading.Thread(target=self._send_commands, daemon=True)
        self._sender.start()

    def now(self) -> float:
        """Return the probe's clock (s): simulated time on a simulated graph."""
        return self.node.get_clock().now().nanoseconds * 1e-9

    def sleep(self, seconds: float, wall_timeout_s: float | None = None) -> None:
        """Wait ``seconds`` of the probe's clock (on a simulated graph: of simulated time)."""
        if not self.simulated:
            time.sleep(seconds)
            return
        start = self.now()
        # The clock may run slower than the wall clock on a loaded machine; it never stops
        # for long (fish_sim waits out a silent host), so a deadline of many times the span.
        deadline = time.monotonic() + (wall_timeout_s or 30.0 + 10.0 * seconds)
        while self.now() < start + seconds:
            assert time.monotonic() < deadline, (
                f'simulated time moved {self.now() - start:.2f} of {seconds} s')
            time.sleep(0.005)

    def _publish_command(self) -> None:
        command = self.command
        if command is not None:
            msg = self._twist()
            msg.linear.x, msg.angular.z = command
            self._pub.publish(msg)

    def _send_commands(self) -> None:
        if self.simulated:
            self._send_in_lockstep()
            return
        period = 1.0 / CMD_RATE_HZ
        due = time.monotonic()
        while not self._stopping:
            self._publish_command()
            due = max(due + period, time.monotonic())
            time.sleep(max(0.0, due - time.monotonic()))

    def _send_in_lockstep(self) -> None:
        """
        Publish cmd_vel at 20 Hz of simulated time, holding the graph's clock at each period.

        At --speed max the graph runs as fast as it answers; a driver outside the lockstep fell
        behind it whenever the loaded machine starved this process, and a second of simulated
        time without cmd_vel made the planner rest the fish in the middle of a phase. So the
        driver holds fish_sim's clock as the planner's own loop does (clock_hold): the clock
        takes no step past the driver's next command until the driver has sent it.
        """
        clock = self.node.get_clock()
        period_ns = round(1e9 / CMD_RATE_HZ)  # a whole number of fish_sim's 10 ms steps
        while clock.now().nanoseconds == 0:  # no /clock heard yet
            if self._stopping:
                return
            time.sleep(0.005)
        due = clock.now().nanoseconds  # a time the clock took: the holds stay on its steps
        while not self._stopping:
            self._publish_command()
            due = max(due + period_ns, clock.now().nanoseconds)
            self._hold.say_due(due)
            while clock.now().nanoseconds < due and not self._stopping:
                time.sleep(0.002)

    def _on_truth(self, msg) -> None:
        import math
        q = msg.pose.pose.orientation
        yaw = 2.0 * math.atan2(q.z, q.w)
        self.recording.truth.append((self.now(), msg.pose.pose.position.x,
                                     msg.pose.pose.position.y, yaw, msg.twist.twist.linear.x,
                                     msg.twist.twist.angular.z))

    def _on_servo(self, msg) -> None:
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        self.recording.servo.append((stamp, *msg.position, *msg.velocity))

    def _on_state(self, msg) -> None:
        self.recording.state.append((self.now(), msg))

    def _on_diagnostics(self, msg) -> None:
        for status in msg.status:
            if status.name.endswith('/planner_node'):
                self.recording.diagnostics.append((self.now(), status))
            elif '/bridge_node:' in status.name:
                self.recording.bridge = {pair.key: pair.value for pair in status.values}

    def set_parameters(self, node_name: str, **values) -> None:
        """Set parameters of a node of the graph (raises if refused)."""
        from rcl_interfaces.srv import SetParameters
        from rclpy.parameter import Parameter

        client = self.node.create_client(SetParameters, f'{node_name}/set_parameters')
        # Discovery: beside two CPU hogs on a slow machine 10 s was not enough.
        assert client.wait_for_service(timeout_sec=FISH_DRIVEN_WAIT_S), \
            f'no {client.srv_name} within {FISH_DRIVEN_WAIT_S:g} s'
        request = SetParameters.Request(parameters=[
            Parameter(k, value=v).to_parameter_msg() for k, v in values.items()])
        future = client.call_async(request)
        deadline = time.monotonic() + 10.0
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.02)
        assert future.done(), f'{client.srv_name} did not answer'
        results = future.result().results
        assert all(r.successful for r in results), [r.reason for r in results]
        self.node.destroy_client(client)

    def close(self) -> None:
        """Stop spinning and destroy the node."""
        self._stopping = True
        wake(self._executor)
        self._sender.join(timeout=5.0)
        self._spinner.join(timeout=5.0)
        self.node.destroy_node()


@pytest.fixture(scope='module')
def planner_domain_id() -> int:
    """Return the ROS domain of this module's graph (outside the per-test window)."""
    return int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19


@pytest.fixture(scope='module')
def simulated_planner_graph(planner_domain_id: int, tmp_path_factory,
                            request: pytest.FixtureRequest) -> Iterator[PlannerGraph]:
    """
    Yield the module's graph on fish_sim's clock; stop it afterwards.

    At the module's ``GRAPH_SPEED`` (fish_sim --speed; default ``1``).
    """
    graph = start_planner_graph(planner_domain_id, fish_flags=(
        '--yaw-disturbance', str(YAW_DISTURBANCE_RAD_S)),
        speed=getattr(request.module, 'GRAPH_SPEED', '1'),
        directory=tmp_path_factory.mktemp('simulated_planner'))
    try:
        yield graph
    finally:
        codes = stop_planner_graph(graph)
        assert not graph.link.exists(), 'fish_sim left its pty link behind'
        print('exit codes:', codes)


@pytest.fixture(scope='module')
def driver(simulated_planner_graph: PlannerGraph) -> Iterator[Driver]:
    """
    Yield the module's driver node on the graph's domain and clock, in a context of its own.

    Once the bridge says the fish hears it (as `wirefish mission` waits): a bridge that has not
    yet heard the graph's clock sends no heartbeat, and the fish ignores every command.
    """
    from wirefish_operator.verb.mission import fish_hears_host

    planner_graph = simulated_planner_graph
    with domain_context(planner_graph.domain_id) as context:
        probe = Driver(context, planner_graph.namespace, simulated=planner_graph.simulated)
        try:
            deadline = time.monotonic() + FISH_DRIVEN_WAIT_S
            while not fish_hears_host(probe.recording.bridge):
                assert time.monotonic() < deadline, \
                    f'the bridge never said its fish hears it: {probe.recording.bridge}'
                time.sleep(0.1)
            yield probe
        finally:
            probe.command = None
            probe.close()
