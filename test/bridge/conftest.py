# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the bridge tests: fish_sim and bridge_node processes, a probe, a fake device."""

from collections.abc import Callable, Iterator
import os
from pathlib import Path
import select
import subprocess
import sys
import time
import tty

from ament_index_python.packages import get_package_prefix
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Vector3Stamped
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data, QoSProfile, ReliabilityPolicy
from ros_utils import spin_until
from sensor_msgs.msg import BatteryState, Imu, JointState
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import Heartbeat, ProtocolMessage, Role

BIN = Path(get_package_prefix('wirefish_bridge')) / 'lib' / 'wirefish_bridge'
SIM_BIN = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim'


@pytest.fixture
def fish_sim_exe() -> Path:
    """Return the installed fish_sim executable."""
    return SIM_BIN / 'fish_sim'


@pytest.fixture
def start_fish(spawn) -> Callable[..., subprocess.Popen]:
    """Return ``start(link, *flags)``: a fish_sim on ``link``, started once the link exists."""
    def start(link: Path, *flags: str) -> subprocess.Popen:
        proc = spawn([str(SIM_BIN / 'fish_sim'), '--link', str(link), *flags])
        deadline = time.monotonic() + 10.0
        while not link.is_symlink() and time.monotonic() < deadline:
            assert proc.poll() is None, proc.stdout.read()
            time.sleep(0.02)
        assert link.is_symlink()
        return proc
    return start


@pytest.fixture
def start_bridge(spawn) -> Callable[..., subprocess.Popen]:
    """Return ``start(port, *params, namespace='')``: a bridge_node with ``-p`` params."""
    def start(port: Path | str, *params: str, namespace: str = '') -> subprocess.Popen:
        args = [str(BIN / 'bridge_node'), '--ros-args', '-p', f'port:={port}']
        for param in params:
            args += ['-p', param]
        if namespace:
            args += ['-r', f'__ns:={namespace}']
        return spawn(args)
    return start


# Samples the probe keeps per topic between two spins (100 Hz streams: 10 s of them).
PROBE_DEPTH = 1000


class Probe:
    """A test node recording imu/data, servo_state and /diagnostics, publishing servo_cmd."""

    def __init__(self, context, namespace: str = '') -> None:
        self.node = rclpy.create_node('bridge_probe', namespace=namespace, context=context)
        self.imu, self.servo, self.diagnostics = [], [], []
        self.attitude, self.battery = [], []
        # Best effort as the bridge offers them, with room for every sample of a second or more:
        # a probe starved by a loaded machine must not drop what the bridge published (its
        # rates are the claims here), as the sensor-data depth of 5 did.
        heard = QoSProfile(depth=PROBE_DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.node.create_subscription(Imu, 'imu/data', self.imu.append, heard)
        self.node.create_subscription(Vector3Stamped, 'attitude', self.attitude.append, heard)
        self.node.create_subscription(BatteryState, 'battery', self.battery.append, heard)
        self.node.create_subscription(JointState, 'servo_state', self.servo.append, heard)
        self.node.create_subscription(DiagnosticArray, '/diagnostics', self.diagnostics.append,
                                      10)
        self.cmd = self.node.create_publisher(JointState, 'servo_cmd', qos_profile_sensor_data)
        self.last_command_s: float | None = None  # the node clock's time of the newest servo_cmd
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)

    def spin_for(self, seconds: float, command=None, rate_hz: float = 100.0) -> None:
        deadline = time.monotonic() + seconds
        next_cmd = time.monotonic()
        while time.monotonic() < deadline:
            if command is not None and time.monotonic() >= next_cmd:
                self.cmd.publish(JointState(name=['servo_1', 'servo_2'], position=command))
                self.last_command_s = self.node.get_clock().now().nanoseconds * 1e-9
                next_cmd += 1.0 / rate_hz
            self.executor.spin_once(timeout_sec=0.002)

    def command_until_measured(self, command: list[float], timeout_s: float = 20.0,
                               tolerance_rad: float = 1e-3) -> bool:
        """
        Stream ``command`` on servo_cmd until servo_state reads it back; return whether it did.

        The servos slew and lag, and on a loaded machine the fish's simulated time can run
        behind the wall clock: how long they take is not the claim, that they get there is.
        """
        def measured() -> bool:
            return bool(self.servo) and all(
                abs(got - want) <= tolerance_rad
                for got, want in zip(self.servo[-1].position, command, strict=True))
        deadline = time.monotonic() + timeout_s
        while not measured() and time.monotonic() < deadline:
            self.spin_for(0.1, command=command)
        return measured()

    def statuses(self, node: str = '') -> list[DiagnosticStatus]:
        """Return the bridge statuses received so far, of ``node`` (a name prefix) if given."""
        return [s for array in self.diagnostics for s in array.status
                if 'serial link' in s.name and s.name.startswith(node)]

    def last_diagnostics(self, node: str = '') -> dict[str, str]:
        """Return the values of the newest bridge status (of ``node`` if given)."""
        return {kv.key: kv.value for kv in self.statuses(node)[-1].values}

    def set_parameters(self, node: str, parameters: list) -> list:
        """Set ``parameters`` (rclpy Parameters) on ``node`` (its full name); return results."""
        from rcl_interfaces.srv import SetParameters
        client = self.node.create_client(SetParameters, f'{node}/set_parameters')
        assert spin_until(self.executor, client.service_is_ready, 20.0)
        future = client.call_async(SetParameters.Request(
            parameters=[p.to_parameter_msg() for p in parameters]))
        assert spin_until(self.executor, future.done, 10.0)
        self.node.destroy_client(client)
        return future.result().results

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


@pytest.fixture
def probe(ros_context) -> Iterator[Probe]:
    """Yield a probe node in the root namespace of this test's domain."""
    p = Probe(ros_context)
    yield p
    p.close()


class FakeDevice:
    """
    The master side of a pty pair held by the test; its slave's path is behind ``link``.

    The test plays whatever is on the other end of the bridge's port: a fish (``send``
    frames encoded by the codec) or an unrelated terminal (never sends a frame).
    """

    def __init__(self, link: Path) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.link = link
        os.symlink(os.ttyname(self.slave), link)
        self.encoder = FrameEncoder()
        self.decoder = StreamDecoder()
        self.received = bytearray()

    def send(self, *messages: ProtocolMessage) -> None:
        os.write(self.master, b''.join(self.encoder.encode(m) for m in messages))

    def send_fish_heartbeat(self) -> None:
        self.send(Heartbeat(role=Role.FISH))

    def read_available(self) -> bytes:
        """Return (and keep in ``received``) every byte the bridge wrote since the last call."""
        chunk = bytearray()
        while select.select([self.master], [], [], 0.0)[0]:
            try:
                data = os.read(self.master, 4096)
            except OSError:   # EIO: nobody has the slave open right now
                break
            if not data:
                break
            chunk += data
        self.received += chunk
        return bytes(chunk)

    def messages(self) -> list[ProtocolMessage]:
        """Return the messages in the bytes the bridge wrote since the last call."""
        return [f.message for f in self.decoder.feed(self.read_available())]

    def close(self) -> None:
        os.close(self.master)
        os.close(self.slave)


@pytest.fixture
def fake_device(tmp_path: Path) -> Iterator[FakeDevice]:
    """Yield a pty pair held by the test, its slave behind ``tmp_path / 'tty'``."""
    device = FakeDevice(tmp_path / 'tty')
    yield device
    device.close()


@pytest.fixture
def terminal_of_a_shell(fake_device: FakeDevice) -> Iterator[int]:
    """Make ``fake_device`` the controlling terminal of a waiting process; yield its pid."""
    path = os.ttyname(fake_device.slave)
    shell = subprocess.Popen([sys.executable, '-c',
                              f'import os, sys; os.setsid(); os.open({path!r}, os.O_RDWR); '
                              'print(flush=True); sys.stdin.read()'],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    shell.stdout.readline()   # from here on the device is its controlling terminal
    yield shell.pid
    shell.communicate('')
