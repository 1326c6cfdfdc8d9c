# SPDX-License-Identifier: Apache-2.0
"""
Servo calibration from the shore, on the virtual fish's road: fish_sim, bridge_node, the verb.

One graph for the module (fish_sim on a pty with a calibration file, bridge_node on it, on a
domain of its own), shared by the tests in file order: a live trim moves the virtual reel and
is reported LIVE (service answer and latched servo_calibration); a refused request changes
nothing; a saved one is STORED after fish_sim starts again on its file; FACTORY gives the
defaults; a sweep turns the servo both ways and is refused in gait mode; `wirefish calibrate
show` prints both servos, and names what it waited for when no bridge answers.
"""

from collections.abc import Iterator
from dataclasses import dataclass
import math
import os
from pathlib import Path
import shutil
import subprocess
import time

from ament_index_python.packages import get_package_prefix
import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from ros_utils import spin_until, stop_process
from sensor_msgs.msg import JointState
from wirefish_common.qos import LATCHED
from wirefish_msgs.msg import ServoCalibration, ServoTrimReport
from wirefish_msgs.srv import ServoSweep, ServoTrim

pytestmark = pytest.mark.ros

NAMESPACE = '/calibration_test'
SIM = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim' / 'fish_sim'
BRIDGE = Path(get_package_prefix('wirefish_bridge')) / 'lib' / 'wirefish_bridge' / 'bridge_node'
DEFAULT_PER_RAD = 636.619772
# The reel settles within the servo model's lag (20 ms) once the trim is in force; the
# IMU-free servo angle is exact to float32 rounding of the telemetry.
REEL_TOLERANCE_RAD = 2e-3


@dataclass
class Graph:
    """The module's processes, its probe node and what the probe heard."""

    env: dict
    link: Path
    calibration: Path
    fish: subprocess.Popen
    bridge: subprocess.Popen
    context: Context
    node: object
    executor: SingleThreadedExecutor
    client: object
    servo_state: list
    calibrations: list

    def start_fish(self) -> subprocess.Popen:
        self.fish = _spawn([str(SIM), '--link', str(self.link), '--calibration',
                            str(self.calibration), '--imu-noise-scale', '0'], self.env)
        deadline = time.monotonic() + 10.0
        while not self.link.is_symlink() and time.monotonic() < deadline:
            assert self.fish.poll() is None, self.fish.stdout.read()
            time.sleep(0.02)
        assert self.link.is_symlink()
        return self.fish

    def trim(self, servo: int, op: int, direction: int = 0, neutral_us: float = 0.0,
             us_per_rad: float = 0.0, timeout_s: float = 10.0):
        future = self.client.call_async(ServoTrim.Request(
            servo=servo, op=op, direction=direction, neutral_us=neutral_us,
            us_per_rad=us_per_rad))
        assert spin_until(self.executor, future.done, timeout_s), 'servo_trim did not answer'
        return future.result()

    def sweep(self, servo: int, amplitude_rad: float, period_s: float):
        client = self.node.create_client(ServoSweep, 'servo_sweep')
        try:
            assert spin_until(self.executor, client.service_is_ready, 10.0)
            future = client.call_async(ServoSweep.Request(
                servo=servo, amplitude_rad=amplitude_rad, period_s=period_s))
            assert spin_until(self.executor, future.done, 10.0), 'servo_sweep did not answer'
            return future.result()
        finally:
            self.node.destroy_client(client)

    def set_drive_mode(self, mode: str) -> None:
        from rcl_interfaces.srv import SetParameters
        from rclpy.parameter import Parameter
        client = self.node.create_client(SetParameters, f'{NAMESPACE}/bridge_node/set_parameters')
        try:
            assert spin_until(self.executor, client.service_is_ready, 10.0)
            future = client.call_async(SetParameters.Request(
                parameters=[Parameter('drive_mode', value=mode).to_parameter_msg()]))
            assert spin_until(self.executor, future.done, 10.0)
            assert future.result().results[0].successful
        finally:
            self.node.destroy_client(client)

    def read_until(self, servo: int, predicate, timeout_s: float):
        """READ ``servo`` until ``predicate(answer)`` (the link may be coming back)."""
        deadline = time.monotonic() + timeout_s
        answer = None
        while time.monotonic() < deadline:
            answer = self.trim(servo, ServoTrim.Request.OP_READ)
            if predicate(answer):
                return answer
            spin_until(self.executor, lambda: False, 0.3)
        return answer


def _spawn(args: list[str], env: dict) -> subprocess.Popen:
    return subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)


@pytest.fixture(scope='module')
def graph(tmp_path_factory) -> Iterator[Graph]:
    """Start fish_sim and bridge_node once for the module; stop both at its end."""
    domain = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               PYTHONUNBUFFERED='1', RCUTILS_COLORIZED_OUTPUT='0')
    home = tmp_path_factory.mktemp('calibration')
    env['ROS_HOME'] = str(home / 'ros_home')
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('calibration_probe', namespace=NAMESPACE, context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    g = Graph(env, home / 'tty', home / 'calibration.bin', None, None, context, node, executor,
              node.create_client(ServoTrim, 'servo_trim'), [], [])
    node.create_subscription(JointState, 'servo_state', g.servo_state.append,
                             qos_profile_sensor_data)
    node.create_subscription(ServoCalibration, 'servo_calibration', g.calibrations.append,
                             LATCHED)
    try:
        g.start_fish()
        g.bridge = _spawn([str(BRIDGE), '--ros-args', '-p', f'port:={g.link}', '-r',
                           f'__ns:={NAMESPACE}'], env)
        assert spin_until(executor, g.client.service_is_ready, 30.0), 'no servo_trim service'
        yield g
    finally:
        for proc in (g.bridge, g.fish):
            if proc is not None:
                stop_process(proc)
                proc.stdout.close()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def _reel_1(graph: Graph, seconds: float) -> float:
    """Return servo_1's mean reported angle over the last ``seconds`` of spinning."""
    start = len(graph.servo_state)
    spin_until(graph.executor, lambda: False, seconds)
    angles = [m.position[0] for m in graph.servo_state[start:]]
    assert angles, 'no servo_state'
    return sum(angles[len(angles) // 2:]) / len(angles[len(angles) // 2:])


def test_a_live_trim_moves_the_virtual_reel_and_is_reported_live(graph: Graph):
    before = _reel_1(graph, 1.0)
    answer = graph.trim(1, ServoTrim.Request.OP_SET, 1, 1550.0, 600.0)
    after = _reel_1(graph, 1.0)
    assert spin_until(graph.executor, lambda: graph.calibrations
                      and graph.calibrations[-1].servo_1.source == ServoTrimReport.SOURCE_LIVE,
                      5.0)
    latched = graph.calibrations[-1].servo_1
    print(f'servo_1 at command 0: {before:+.4f} rad before, {after:+.4f} rad after neutral '
          f'1550 us (expected +{50.0 / DEFAULT_PER_RAD:.4f}); answer {answer.reason!r}')
    assert answer.accepted, answer.reason
    assert answer.calibration.source == ServoTrimReport.SOURCE_LIVE
    assert (answer.calibration.neutral_us, answer.calibration.us_per_rad) == (1550.0, 600.0)
    assert (latched.neutral_us, latched.us_per_rad, latched.direction) == (1550.0, 600.0, 1)
    assert abs(before) < REEL_TOLERANCE_RAD
    assert after == pytest.approx(50.0 / DEFAULT_PER_RAD, abs=REEL_TOLERANCE_RAD)


@pytest.mark.parametrize('request_args, words', [
    ((1, 1, 1, math.nan, 600.0), 'not finite'),
    ((3, 1, 1, 1500.0, 600.0), 'servo 3'),
    ((2, 2, 0, 1500.0, 600.0), 'direction 0'),
])
def test_a_refused_request_changes_nothing(graph: Graph, request_args, words):
    before = graph.trim(request_args[0] if request_args[0] in (1, 2) else 1,
                        ServoTrim.Request.OP_READ)
    answer = graph.trim(*request_args)
    after = graph.trim(request_args[0] if request_args[0] in (1, 2) else 1,
                       ServoTrim.Request.OP_READ)
    assert not answer.accepted and words in answer.reason
    assert after.calibration == before.calibration


def test_a_saved_trim_is_stored_after_fish_sim_starts_again(graph: Graph):
    answer = graph.trim(2, ServoTrim.Request.OP_SAVE, -1, 1490.0, 610.0)
    assert answer.accepted, answer.reason
    assert answer.calibration.source == ServoTrimReport.SOURCE_STORED
    stop_process(graph.fish)
    graph.fish.stdout.close()
    graph.start_fish()
    started = time.monotonic()
    read = graph.read_until(2, lambda a: a.accepted, 30.0)
    one = graph.trim(1, ServoTrim.Request.OP_READ)
    print(f'after the restart: servo 2 read back in {time.monotonic() - started:.1f} s: '
          f'source {read.calibration.source}, servo 1 source {one.calibration.source}')
    assert read.accepted, read.reason
    stored = read.calibration
    assert (stored.source, stored.direction, stored.neutral_us, stored.us_per_rad) == (
        ServoTrimReport.SOURCE_STORED, -1, 1490.0, 610.0)
    assert one.calibration.source == ServoTrimReport.SOURCE_DEFAULTS   # live was not saved


def test_factory_gives_the_build_s_defaults(graph: Graph):
    answer = graph.trim(2, ServoTrim.Request.OP_FACTORY)
    assert answer.accepted, answer.reason
    cal = answer.calibration
    assert (cal.source, cal.direction, cal.neutral_us) == (
        ServoTrimReport.SOURCE_DEFAULTS, 1, 1500.0)
    assert cal.us_per_rad == pytest.approx(DEFAULT_PER_RAD, abs=1e-3)


def test_a_sweep_turns_its_servo_both_ways_and_holds_the_other(graph: Graph):
    spin_until(graph.executor, lambda: False, 0.5)   # the last test's reel settles (20 ms lag)
    start = len(graph.servo_state)
    answer = graph.sweep(1, 0.3, 2.0)
    spin_until(graph.executor, lambda: False, 2.5)
    angles = [tuple(m.position) for m in graph.servo_state[start:]]
    peak, trough = max(a[0] for a in angles), min(a[0] for a in angles)
    other = max(abs(a[1]) for a in angles)
    print(f'sweep of servo 1 by 0.3 rad: {peak:+.3f} .. {trough:+.3f} rad, servo 2 within '
          f'{other:.4f} rad')
    assert answer.accepted, answer.reason
    assert peak == pytest.approx(0.3, abs=0.03) and trough == pytest.approx(-0.3, abs=0.03)
    assert other < REEL_TOLERANCE_RAD


def test_a_sweep_is_refused_in_gait_mode_with_how_to_switch(graph: Graph):
    graph.set_drive_mode('gait')
    try:
        answer = graph.sweep(2, 0.3, 2.0)
    finally:
        graph.set_drive_mode('stream')
    assert not answer.accepted
    assert f'ros2 param set {NAMESPACE}/bridge_node drive_mode stream' in answer.reason


def test_the_verb_show_prints_both_servos(graph: Graph):
    wirefish = shutil.which('wirefish')
    assert wirefish is not None
    done = subprocess.run([wirefish, 'calibrate', '--namespace', NAMESPACE, 'show'],
                          env=graph.env, capture_output=True, text=True, timeout=60)
    print(done.stdout, done.stderr)
    assert done.returncode == 0, done.stderr
    rows = [line.split() for line in done.stdout.splitlines()]
    assert [row[:2] for row in rows[1:]] == [['1', 'DEFAULTS'], ['2', 'DEFAULTS']]


def test_the_verb_names_what_it_waited_for_when_no_bridge_answers(graph: Graph):
    wirefish = shutil.which('wirefish')
    assert wirefish is not None
    done = subprocess.run([wirefish, 'calibrate', '--namespace', '/nobody_here', '--timeout',
                           '1', 'show'], env=graph.env, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 1
    assert ('no bridge found in /nobody_here: waited 1 s for its /nobody_here/servo_trim'
            in done.stderr), done.stderr
