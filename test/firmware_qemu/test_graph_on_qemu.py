# SPDX-License-Identifier: Apache-2.0
"""
The whole graph on the emulated board: `wirefish up --fish qemu`, as a user starts it.

The bridge's streams at their registry rates, a QEMU restarted under the running graph,
`wirefish calibrate` trimming the emulated board live and back, and Ctrl-C leaving no QEMU
behind. The emulated board has no physics: sim/ground_truth is absent.
"""

from collections.abc import Iterator
from dataclasses import dataclass
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from e2e_utils import descendants, lines_until_running, OWN_NAMESPACE
import psutil
import pytest
from rclpy.qos import qos_profile_sensor_data
from ros_utils import domain_context, probe_node, spin_until, stop_process
from sensor_msgs.msg import JointState
from wirefish_bringup.graph import entry
from wirefish_launcher.monitor import measure_rates

pytestmark = [pytest.mark.ros, pytest.mark.loads_machine]

NAMESPACE = '/qemu_graph'
BRIDGE = entry('bridge_node')
RATE_TOLERANCE = 0.10
WINDOW_S = 30.0


@dataclass
class QemuGraph:
    """A `wirefish up --fish qemu` process and the QEMU processes seen under it."""

    launcher: subprocess.Popen
    domain_id: int
    qemu_pids: set[int]
    env: dict[str, str]

    def qemu_processes(self) -> list[psutil.Process]:
        found = [p for p in descendants(self.launcher.pid) if _is_qemu(p)]
        self.qemu_pids.update(p.pid for p in found)
        return found

    def process(self, name: str) -> psutil.Process:
        return next(p for p in descendants(self.launcher.pid)
                    if name in ' '.join(_cmdline(p)))


def _cmdline(process: psutil.Process) -> list[str]:
    try:
        return process.cmdline()
    except psutil.Error:
        return []


def _is_qemu(process: psutil.Process) -> bool:
    line = _cmdline(process)
    return bool(line) and os.path.basename(line[0]) == 'qemu-system-arm'


@pytest.fixture(scope='module')
def qemu_graph(tmp_path_factory) -> Iterator[QemuGraph]:
    """Yield a running `wirefish up --fish qemu` on a domain of its own."""
    domain_id = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    launcher = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--fish', 'qemu', '--no-status',
         *OWN_NAMESPACE, '--namespace', NAMESPACE,
         '--out', str(tmp_path_factory.mktemp('qemu_run'))],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    graph = QemuGraph(launcher, domain_id, set(), env)
    try:
        seen = lines_until_running(launcher, 90.0)
        assert seen and seen[-1].startswith('running:'), ''.join(seen)
        graph.qemu_processes()
        yield graph
    finally:
        children = descendants(launcher.pid)
        stop_process(launcher, timeout_s=20.0)
        for child in children:
            if child.is_running():
                child.kill()
        launcher.stdout.close()


@pytest.fixture
def graph_node(qemu_graph: QemuGraph):
    with domain_context(qemu_graph.domain_id) as context, \
            probe_node('qemu_graph_probe', context) as node_and_executor:
        yield node_and_executor


def _full(topic: str) -> str:
    return topic if topic.startswith('/') else f'{NAMESPACE}/{topic}'


def test_without_a_firmware_tree_wirefish_up_fails_with_one_line(tmp_path):
    env = dict(os.environ, WIREFISH_FIRMWARE_DIR=str(tmp_path / 'nowhere'))
    result = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--fish', 'qemu', '--no-status',
         '--namespace', '/qemu_missing', '--out', str(tmp_path)],
        env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 1, result.stdout + result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and 'no firmware source tree' in lines[0], result.stderr
    assert 'started' not in result.stdout   # nothing was started


def test_every_bridge_stream_at_its_rate_for_30_s(qemu_graph, graph_node):
    node, executor = graph_node
    wanted = [_full(t) for t in [*BRIDGE.rates_hz, *BRIDGE.min_rates_hz]]
    assert spin_until(executor, lambda: all(node.count_publishers(t) > 0 for t in wanted),
                      timeout_s=30.0), 'bridge topics missing'
    assert node.count_publishers(_full('sim/ground_truth')) == 0   # no physics on the board
    rates = measure_rates(node, executor, NAMESPACE, window_s=WINDOW_S)
    shown = {t: round(rates[_full(t)][1], 1) for t in [*BRIDGE.rates_hz, *BRIDGE.min_rates_hz]}
    print(f'\nwirefish up --fish qemu, {WINDOW_S:g} s: {shown} (nominal {dict(BRIDGE.rates_hz)},'
          f' at least {dict(BRIDGE.min_rates_hz)})')
    for topic, nominal in BRIDGE.rates_hz.items():
        assert rates[_full(topic)][1] == pytest.approx(nominal, rel=RATE_TOLERANCE), topic
    for topic, minimum in BRIDGE.min_rates_hz.items():
        assert rates[_full(topic)][1] >= minimum, topic


def test_the_board_holds_its_servos_at_neutral_until_the_first_command(qemu_graph, graph_node):
    from geometry_msgs.msg import Twist

    node, executor = graph_node
    angles: list[float] = []  # what the board reports (the reference firmware echoes its command)
    node.create_subscription(JointState, _full('servo_state'),
                             lambda msg: angles.extend(msg.position), qos_profile_sensor_data)
    assert spin_until(executor, lambda: len(angles) > 2 * 300, timeout_s=30.0)  # 3 s at 100 Hz
    assert max(abs(a) for a in angles) < 1e-3, max(abs(a) for a in angles)
    cmd_vel = node.create_publisher(Twist, _full('cmd_vel'), 10)
    swim = Twist()
    swim.linear.x = 0.2
    since = len(angles)

    def swims() -> bool:
        cmd_vel.publish(swim)
        return any(abs(a) > 0.05 for a in angles[since:])

    assert spin_until(executor, swims, timeout_s=20.0)


def test_qemu_restarted_under_the_running_graph_the_link_comes_back(qemu_graph, graph_node):
    node, executor = graph_node
    received: list[float] = []   # wall-clock times (psutil's process start times are too)
    node.create_subscription(JointState, _full('servo_state'),
                             lambda _msg: received.append(time.time()),
                             qos_profile_sensor_data)
    assert spin_until(executor, lambda: bool(received), timeout_s=20.0)
    bridge = qemu_graph.process('bridge_node')
    old = qemu_graph.qemu_processes()
    assert len(old) == 1
    killed_at = time.time()
    old[0].kill()   # the emulator dies; the graph's supervisor starts a new one

    def new_qemu() -> list[psutil.Process]:
        return [p for p in qemu_graph.qemu_processes() if p.pid != old[0].pid]

    assert spin_until(executor, lambda: bool(new_qemu()), 30.0)
    started = new_qemu()[0].create_time()
    assert spin_until(executor, lambda: sum(t > started for t in received) > 20, 60.0)
    back = next(t for t in received if t > started)
    print(f'\nQEMU killed; a new one {started - killed_at:.2f} s later, servo_state back '
          f'{back - killed_at:.2f} s after the kill, the same bridge_node (pid {bridge.pid}) '
          'and launcher')
    assert bridge.is_running() and qemu_graph.process('bridge_node').pid == bridge.pid
    assert qemu_graph.launcher.poll() is None


def _calibrate(qemu_graph: QemuGraph, *args: str) -> tuple[int, list[list[str]], str]:
    """Run `wirefish calibrate ARGS` on the graph; return its code, its table's rows, stderr."""
    done = subprocess.run([sys.executable, '-m', 'wirefish_cli.cli', 'calibrate', '--namespace',
                           NAMESPACE, *args], env=qemu_graph.env, capture_output=True,
                          text=True, timeout=60)
    print(done.stdout, done.stderr)
    return done.returncode, [line.split() for line in done.stdout.splitlines()[1:]], done.stderr


def test_wirefish_calibrate_reads_the_emulated_boards_build_values(qemu_graph):
    code, rows, stderr = _calibrate(qemu_graph, 'show')
    assert code == 0, stderr
    assert [row[:2] for row in rows] == [['1', 'DEFAULTS'], ['2', 'DEFAULTS']]


def test_wirefish_calibrate_trims_the_emulated_board_live_then_back(qemu_graph):
    code, rows, stderr = _calibrate(qemu_graph, 'set', '1', '--neutral-us', '1520',
                                    '--us-per-rad', '600', '--direction', '-1')
    assert code == 0, stderr
    assert rows[0][:5] == ['1', 'LIVE', '1520.0', '600.00', '-1']
    code, rows, stderr = _calibrate(qemu_graph, 'factory', '1')
    assert code == 0, stderr
    assert rows[0][:2] == ['1', 'DEFAULTS']


def test_ctrl_c_stops_the_graph_and_leaves_no_qemu(qemu_graph):
    qemu_graph.qemu_processes()
    assert qemu_graph.qemu_pids
    os.kill(qemu_graph.launcher.pid, signal.SIGINT)   # what a terminal's Ctrl-C sends
    code = qemu_graph.launcher.wait(timeout=40.0)
    left = [pid for pid in qemu_graph.qemu_pids if psutil.pid_exists(pid)
            and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE]
    output = qemu_graph.launcher.stdout.read()
    print(f'\nCtrl-C: wirefish up exited with {code}; QEMU processes seen '
          f'{sorted(qemu_graph.qemu_pids)}, still running {left}')
    assert not left
    assert not [p for p in psutil.process_iter() if _is_qemu(p)
                and Path(f'/proc/{p.pid}').exists() and p.ppid() == qemu_graph.launcher.pid]
    assert code in (0, 1), output   # 1: the killed QEMU's restart is reported as unclean
