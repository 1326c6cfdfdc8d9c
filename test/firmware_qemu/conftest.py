# SPDX-License-Identifier: Apache-2.0
"""
Fixtures of the in-the-loop tests: the firmware's ARM build on an emulated board (QEMU).

Its debug console, a tap on its link, bridge_node processes and a ROS probe.

The emulator image is built once (make -C firmware qemu). A machine without the ARM toolchain
or QEMU fails here with the line that says what to install (`make setup` installs both as
root): these tests are never skipped.
"""

from collections.abc import Callable, Iterator
from pathlib import Path
import subprocess
import time

from ament_index_python.packages import get_package_prefix
from diagnostic_msgs.msg import DiagnosticArray
import pytest
from qemu_loop import Console, Tap
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import JointState
from wirefish_launcher.errors import QemuBoardError
from wirefish_launcher.qemu_board import build_image, QemuBoard

BRIDGE = Path(get_package_prefix('wirefish_bridge')) / 'lib' / 'wirefish_bridge' / 'bridge_node'


@pytest.fixture(scope='session')
def qemu_image() -> Path:
    """Return the emulator image, built if out of date; fail with what is missing."""
    try:
        return build_image()
    except QemuBoardError as error:
        pytest.fail(f'the firmware-in-the-loop tests need the ARM build: {error}',
                    pytrace=False)


@pytest.fixture
def board(qemu_image: Path, tmp_path: Path) -> Iterator[QemuBoard]:
    """Yield a freshly booted board, its link behind ``tmp_path / 'board-tty'``."""
    qemu = QemuBoard(qemu_image, link=tmp_path / 'board-tty', console=True)
    try:
        qemu.start()
    except QemuBoardError as error:
        pytest.fail(str(error), pytrace=False)
    try:
        yield qemu
    finally:
        qemu.stop()
        qemu.remove_link()


@pytest.fixture
def console(board: QemuBoard) -> Iterator[Console]:
    """Yield the board's debug console once it reported its timer and calibration."""
    assert board.ports is not None and board.ports.console is not None
    reader = Console(board.ports.console)
    deadline = time.monotonic() + 5.0
    while not reader.ready() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert reader.ready(), 'the debug console said nothing within 5 s'
    yield reader
    reader.close()


@pytest.fixture
def tap(board: QemuBoard, console: Console, tmp_path: Path) -> Iterator[Tap]:
    """Yield a tap on the board's link; the bridge's port is ``tap.link``."""
    assert board.ports is not None
    relay = Tap(tmp_path / 'tap-tty', board.ports.link)
    yield relay
    relay.close()


@pytest.fixture
def start_bridge(spawn, tmp_path: Path) -> Callable[..., subprocess.Popen]:
    """Return ``start(port, *params)``: a bridge_node, its output in ``tmp_path/bridge.log``."""
    def start(port: Path | str, *params: str) -> subprocess.Popen:
        args = [str(BRIDGE), '--ros-args', '-p', f'port:={port}']
        for param in params:
            args += ['-p', param]
        log = open(tmp_path / 'bridge.log', 'w')
        return spawn(args, stdout=log, stderr=subprocess.STDOUT)
    return start


class Probe:
    """A test node: publishes servo_cmd, records servo_state and the bridge's diagnostics."""

    def __init__(self, context) -> None:
        self.node = rclpy.create_node('qemu_loop_probe', context=context)
        self.servo_state: list[tuple[float, JointState]] = []
        self.diagnostics: list[DiagnosticArray] = []
        self.node.create_subscription(
            JointState, 'servo_state',
            lambda msg: self.servo_state.append((time.monotonic(), msg)), qos_profile_sensor_data)
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self.diagnostics.append,
                                      10)
        self.cmd = self.node.create_publisher(JointState, 'servo_cmd', qos_profile_sensor_data)
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.published = 0

    def publish(self, angles: tuple[float, float]) -> None:
        self.cmd.publish(JointState(name=['servo_1', 'servo_2'], position=list(angles)))
        self.published += 1

    def spin_for(self, seconds: float,
                 command: Callable[[int], tuple[float, float]] | None = None,
                 rate_hz: float = 100.0) -> None:
        """Spin ``seconds``; with ``command``, publish command(i) at ``rate_hz``."""
        deadline = time.monotonic() + seconds
        next_cmd = time.monotonic()
        while time.monotonic() < deadline:
            if command is not None and time.monotonic() >= next_cmd:
                self.publish(command(self.published))
                next_cmd += 1.0 / rate_hz
            self.executor.spin_once(timeout_sec=0.001)

    def spin_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if predicate():
                return True
            self.executor.spin_once(timeout_sec=0.05)
        return predicate()

    def last_diagnostics(self) -> dict[str, str]:
        """Return the values of the newest bridge status ({} before the first)."""
        statuses = [s for a in self.diagnostics for s in a.status if 'serial link' in s.name]
        return {kv.key: kv.value for kv in statuses[-1].values} if statuses else {}

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


@pytest.fixture
def probe(ros_context) -> Iterator[Probe]:
    """Yield a probe node in the root namespace of this test's domain."""
    node = Probe(ros_context)
    yield node
    node.close()
