"""
bridge_node: the serial link to the fish's board (STM32F407, §2.1), see PROTOCOL.md.

Subscribes
    ``servo_cmd`` (sensor_msgs/JointState ``servo_1``, ``servo_2``, rad; sensor-data QoS, as the
    CPG publishes it): forwarded as SERVO_CMD frames, at most ``max_command_rate_hz``; when it
    stops for ``command_timeout_s`` (or before the first one) the bridge commands neutral.
Publishes (sensor-data QoS, stamped on receipt with the node clock)
    ``imu/data`` (sensor_msgs/Imu, frame ``imu_frame_id``), ``attitude``
    (geometry_msgs/Vector3Stamped: roll, pitch, yaw rad), ``servo_state`` (sensor_msgs/JointState,
    measured angles), ``battery`` (sensor_msgs/BatteryState); and ``/diagnostics``
    (diagnostic_msgs/DiagnosticArray, reliable) at ``diagnostics_rate_hz``.
The port is read by the transport's thread. Telemetry is published straight from that thread
(publishing is thread-safe): the 100 Hz path then costs no executor wake-up, which was the larger
part of the bridge's CPU and of the bytes -> imu/data latency. Every other frame and link event
reaches the executor through a guard condition, so the executor never waits on the device. An
unplugged device is reopened by the transport with backoff; the node keeps running.
"""

from __future__ import annotations

from collections import deque
import math
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Vector3Stamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import BatteryState, Imu, JointState

from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.command_gate import CommandGate, NEUTRAL
from wirefish_bridge.protocol import (DEFAULT_BAUDRATE, ErrorCode, ErrorReport, Heartbeat,
                                      PROTOCOL_VERSION, Role, ServoCommand, Status, Telemetry)
from wirefish_bridge.ros_messages import (attitude_message, battery_message,
                                          diagnostic_status, imu_message, SERVO_NAMES,
                                          servo_state_message)
from wirefish_bridge.transport import LinkDown, LinkState, LinkWriteError, SerialLink
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import declare, ParameterSpec, validate_update
from wirefish_common.qos import RELIABLE, SENSOR_DATA

PARAMETERS = (
    ParameterSpec('port', '/dev/ttyUSB0', 'Serial device of the fish (a stable path such as '
                  '/dev/serial/by-id/... or the virtual fish symlink); reopened when it returns'),
    ParameterSpec('baudrate', DEFAULT_BAUDRATE, 'Serial baud rate', 1200, 4000000),
    ParameterSpec('max_command_rate_hz', 100.0, 'Most servo command frames sent per second',
                  1.0, 1000.0),
    ParameterSpec('command_timeout_s', 0.5,
                  'servo_cmd silence after which the bridge commands neutral (s)', 0.02, 10.0),
    ParameterSpec('servo_limit_rad', math.pi / 2, 'Commands are clamped to +-this (rad)',
                  0.0, math.pi),
    ParameterSpec('heartbeat_rate_hz', 5.0, 'Rate of the host heartbeat (Hz)', 0.5, 50.0),
    ParameterSpec('heartbeat_timeout_s', 1.0,
                  'Fish heartbeat age above which the link is reported stale (s)', 0.1, 10.0),
    ParameterSpec('reconnect_backoff_min_s', 0.1, 'First retry delay after a lost port (s)',
                  0.01, 5.0),
    ParameterSpec('reconnect_backoff_max_s', 1.0, 'Longest retry delay (s); doubles up to it',
                  0.01, 30.0),
    ParameterSpec('diagnostics_rate_hz', 1.0, 'Rate of /diagnostics (Hz)', 0.1, 10.0),
    ParameterSpec('imu_frame_id', 'imu_link', 'frame_id of imu/data and attitude'),
    ParameterSpec('orientation_stddev_rad', 0.0175,
                  'Roll and pitch standard deviation (rad) for the covariance; 0 = unknown',
                  0.0, math.pi),
    ParameterSpec('yaw_stddev_rad', 0.1,
                  'Yaw standard deviation (rad); no magnetometer, yaw drifts; 0 = unknown',
                  0.0, math.pi),
    ParameterSpec('angular_velocity_stddev_rad_s', 0.005,
                  'Gyro standard deviation (rad/s); 0 = unknown', 0.0, 10.0),
    ParameterSpec('linear_acceleration_stddev_m_s2', 0.05,
                  'Accelerometer standard deviation (m/s^2); 0 = unknown', 0.0, 100.0),
)
SPECS = {spec.name: spec for spec in PARAMETERS}
LINK_PARAMETERS = {'port', 'baudrate', 'reconnect_backoff_min_s', 'reconnect_backoff_max_s'}


def check_combination(values: dict[str, object]) -> str | None:
    """Return why a full set of parameter values is inconsistent, or None."""
    if values['reconnect_backoff_max_s'] < values['reconnect_backoff_min_s']:
        return 'reconnect_backoff_max_s must be >= reconnect_backoff_min_s'
    # An all-zero covariance means "unknown"; one zero beside non-zero ones would claim that
    # angle perfectly known.
    if (values['orientation_stddev_rad'] == 0.0) != (values['yaw_stddev_rad'] == 0.0):
        return ('orientation_stddev_rad and yaw_stddev_rad must both be > 0, or both 0 '
                '(orientation covariance unknown)')
    return None


class BridgeNode(Node):
    """Wires servo_cmd to the serial link and the fish's telemetry to ROS topics."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, wire topics and timers, start the serial link."""
        super().__init__('bridge_node', **kwargs)
        declare(self, PARAMETERS, check_combination)
        self._values = {s.name: self.get_parameter(s.name).value for s in PARAMETERS}
        self._started = time.monotonic()
        self._encoder = FrameEncoder()
        self._decoder = StreamDecoder()
        self._gate = CommandGate(self._values['max_command_rate_hz'],
                                 self._values['command_timeout_s'],
                                 self._values['servo_limit_rad'])
        self._inbox: deque = deque(maxlen=1000)  # reader thread -> executor; bounded
        self._inbox_lock = threading.Lock()
        self._frames_out = 0
        self._frames_out_dropped = 0
        self._fish_errors = 0
        self._fish_version: int | None = None
        self._fish_status = 0
        self._last_heartbeat: float | None = None
        self._last_telemetry: float | None = None
        self._rate_window = (time.monotonic(), 0, 0)

        self._imu_pub = self.create_publisher(Imu, 'imu/data', SENSOR_DATA)
        self._attitude_pub = self.create_publisher(Vector3Stamped, 'attitude',
                                                   SENSOR_DATA)
        self._servo_pub = self.create_publisher(JointState, 'servo_state',
                                                SENSOR_DATA)
        self._battery_pub = self.create_publisher(BatteryState, 'battery',
                                                  SENSOR_DATA)
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', RELIABLE)
        self.create_subscription(JointState, 'servo_cmd', self._on_servo_cmd,
                                 SENSOR_DATA)
        self._wake = self.create_guard_condition(self._drain_inbox)
        self._bridge_timers = {}
        self._make_timers()
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self._link = self._make_link()
        self._link.start()

    # --- parameters -------------------------------------------------------------------------
    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        return validate_update(SPECS, self._values, parameters, check_combination)

    def _apply(self, parameters: list[Parameter]) -> None:
        names = {p.name for p in parameters if p.name in SPECS}
        for name in names:
            self._values[name] = self.get_parameter(name).value
        self._gate.max_rate_hz = self._values['max_command_rate_hz']
        self._gate.timeout_s = self._values['command_timeout_s']
        self._gate.limit_rad = self._values['servo_limit_rad']
        if names & {'max_command_rate_hz', 'heartbeat_rate_hz', 'diagnostics_rate_hz'}:
            self._make_timers()
        if names & LINK_PARAMETERS:
            self._link.stop()
            self._link = self._make_link()
            self._link.start()

    def _make_timers(self) -> None:
        for timer in self._bridge_timers.values():
            self.destroy_timer(timer)
        # The command tick releases held commands and checks the failsafe; >= 20 Hz so the
        # failsafe reacts within 50 ms of command_timeout_s whatever the rate limit.
        tick_hz = max(20.0, self._values['max_command_rate_hz'])
        self._bridge_timers = {
            'command': self.create_timer(1.0 / tick_hz, self._on_command_tick),
            'heartbeat': self.create_timer(1.0 / self._values['heartbeat_rate_hz'],
                                           self._send_heartbeat),
            'diagnostics': self.create_timer(1.0 / self._values['diagnostics_rate_hz'],
                                             self._publish_diagnostics),
        }

    def _make_link(self) -> SerialLink:
        self._decoder = StreamDecoder()
        return SerialLink(self._values['port'], self._values['baudrate'], self._on_bytes,
                          self._on_link_state,
                          backoff_min_s=self._values['reconnect_backoff_min_s'],
                          backoff_max_s=self._values['reconnect_backoff_max_s'])

    # --- reader thread side: decode, publish telemetry, hand the rest over ------------------
    def _on_bytes(self, chunk: bytes) -> None:
        others = []
        for frame in self._decoder.feed(chunk):
            if isinstance(frame.message, Telemetry):
                self._publish_from_reader(frame.message)
            else:
                others.append(frame)
        if others:
            with self._inbox_lock:
                self._inbox.extend(others)
            self._wake.trigger()

    def _publish_from_reader(self, telemetry: Telemetry) -> None:
        try:
            self._publish_telemetry(telemetry)
        except Exception as error:  # noqa: B902 (the reader thread must survive; say why)
            if self.context.ok():  # after shutdown (Ctrl-C) there is nothing to say
                self.get_logger().error(f'telemetry not published: {error!r}',
                                        throttle_duration_sec=2.0)

    def _on_link_state(self, state: LinkState, detail: str) -> None:
        if state is LinkState.CONNECTED:
            self._decoder.reset_sequence()
        with self._inbox_lock:
            self._inbox.append((state, detail))
        self._wake.trigger()

    # --- executor side ----------------------------------------------------------------------
    def _drain_inbox(self) -> None:
        with self._inbox_lock:
            items = list(self._inbox)
            self._inbox.clear()
        for item in items:
            if isinstance(item, tuple):
                state, detail = item
                if state is LinkState.CONNECTED:
                    self.get_logger().info(f'link {state.value}: {detail}')
                else:
                    self.get_logger().warn(f'link {state.value}: {detail}')
                continue
            message = item.message
            if isinstance(message, Heartbeat):
                self._on_heartbeat(message)
            elif isinstance(message, ErrorReport):
                self._fish_errors += 1
                self.get_logger().warn(
                    f'fish reports error {_error_name(message.code)} about frame '
                    f'{message.ref_seq}', throttle_duration_sec=2.0)

    def _publish_telemetry(self, telemetry: Telemetry) -> None:
        self._last_telemetry = time.monotonic()
        self._fish_status = telemetry.status
        stamp = self.get_clock().now().to_msg()
        frame_id = self._values['imu_frame_id']
        tilt = self._values['orientation_stddev_rad']
        self._imu_pub.publish(imu_message(
            telemetry, stamp, frame_id, (tilt, tilt, self._values['yaw_stddev_rad']),
            self._values['angular_velocity_stddev_rad_s'],
            self._values['linear_acceleration_stddev_m_s2']))
        self._attitude_pub.publish(attitude_message(telemetry, stamp, frame_id))
        self._servo_pub.publish(servo_state_message(telemetry, stamp))
        self._battery_pub.publish(battery_message(
            telemetry, stamp, bool(telemetry.status & Status.LOW_BATTERY)))

    def _on_heartbeat(self, heartbeat: Heartbeat) -> None:
        self._last_heartbeat = time.monotonic()
        if heartbeat.version != self._fish_version:
            self._fish_version = heartbeat.version
            if heartbeat.version != PROTOCOL_VERSION:
                self.get_logger().error(f'fish speaks protocol version {heartbeat.version}, '
                                        f'this bridge {PROTOCOL_VERSION}')
            else:
                self.get_logger().info(f'fish says hello (protocol {heartbeat.version})')

    def _on_servo_cmd(self, msg: JointState) -> None:
        angles = _servo_angles(msg)
        if angles is None:
            self.get_logger().warn('servo_cmd needs finite positions of servo_1 and servo_2; '
                                   'ignored', throttle_duration_sec=2.0)
            return
        to_send = self._gate.on_command(angles, time.monotonic())
        if to_send is not None:
            self._send(ServoCommand(*to_send))

    def _on_command_tick(self) -> None:
        was_failsafe = self._gate.failsafe
        to_send = self._gate.on_tick(time.monotonic())
        if self._gate.failsafe and not was_failsafe:
            self.get_logger().warn(f'no servo_cmd for {self._gate.timeout_s:g} s: '
                                   'commanding neutral')
        if to_send is not None:
            self._send(ServoCommand(*to_send))

    def _send_heartbeat(self) -> None:
        uptime_ms = int((time.monotonic() - self._started) * 1000.0)
        self._send(Heartbeat(PROTOCOL_VERSION, Role.HOST, uptime_ms))

    def _send(self, message) -> None:
        frame = self._encoder.encode(message)
        try:
            self._link.write(frame)
        except (LinkDown, LinkWriteError):
            self._frames_out_dropped += 1  # the link's state is in /diagnostics
            return
        self._frames_out += 1

    def _publish_diagnostics(self) -> None:
        now = time.monotonic()
        decoder = self._decoder.stats
        link = self._link.stats
        last_time, last_in, last_out = self._rate_window
        elapsed = max(now - last_time, 1e-9)
        frames_in_rate = (decoder.frames_ok - last_in) / elapsed
        frames_out_rate = (self._frames_out - last_out) / elapsed
        self._rate_window = (now, decoder.frames_ok, self._frames_out)
        heartbeat_age = now - self._last_heartbeat if self._last_heartbeat else math.inf
        telemetry_age = now - self._last_telemetry if self._last_telemetry else math.inf
        level, message = self._link_level(heartbeat_age)
        values = {
            'link_state': self._link.state.value, 'port': self._values['port'],
            'frames_in_per_s': frames_in_rate, 'frames_out_per_s': frames_out_rate,
            'frames_in': decoder.frames_ok, 'frames_out': self._frames_out,
            'frames_out_dropped': self._frames_out_dropped, 'bytes_in': decoder.bytes_in,
            'crc_errors': decoder.crc_errors, 'cobs_errors': decoder.cobs_errors,
            'short_frames': decoder.short_frames, 'length_errors': decoder.length_errors,
            'unknown_type': decoder.unknown_type, 'invalid_payload': decoder.invalid_payload,
            'overflows': decoder.overflows, 'resyncs': decoder.resyncs,
            'drops': decoder.seq_gaps, 'last_heartbeat_age_s': heartbeat_age,
            'last_telemetry_age_s': telemetry_age, 'reconnects': link.reconnects,
            'disconnects': link.disconnects, 'open_failures': link.open_failures,
            'last_link_error': link.last_error, 'reader_errors': link.callback_errors,
            'fish_protocol_version': self._fish_version if self._fish_version is not None
            else 'unknown',
            'fish_status': f'0x{self._fish_status:04x} ({_status_names(self._fish_status)})',
            'fish_errors': self._fish_errors, 'failsafe': self._gate.failsafe,
            'failsafe_entries': self._gate.failsafe_entries,
            'commands_clamped': self._gate.clamped,
        }
        array = DiagnosticArray()
        array.header.stamp = self.get_clock().now().to_msg()
        array.status = [diagnostic_status(f'{self.get_name()}: serial link',
                                          self._values['port'], level, message, values)]
        self._diag_pub.publish(array)

    def _link_level(self, heartbeat_age: float) -> tuple[bytes, str]:
        if not self._link.connected:
            return DiagnosticStatus.ERROR, f'{self._link.state.value}: {self._values["port"]}'
        if self._fish_version is not None and self._fish_version != PROTOCOL_VERSION:
            return DiagnosticStatus.ERROR, f'protocol version mismatch ({self._fish_version})'
        if heartbeat_age > self._values['heartbeat_timeout_s']:
            return DiagnosticStatus.WARN, 'connected, fish heartbeat stale'
        if self._gate.failsafe:
            return DiagnosticStatus.WARN, 'connected, no servo_cmd: commanding neutral'
        return DiagnosticStatus.OK, 'connected'

    def destroy_node(self) -> None:
        """Command neutral, stop the serial link (joins its thread, closes the port), the node."""
        # The fish would otherwise hold the last angle until its own command timeout.
        self._send(ServoCommand(*NEUTRAL))
        self._link.stop()
        super().destroy_node()


def _servo_angles(msg: JointState) -> tuple[float, float] | None:
    # By name when names are given (any order), else the first two positions.
    if msg.name:
        try:
            angles = tuple(msg.position[list(msg.name).index(n)] for n in SERVO_NAMES)
        except (ValueError, IndexError):
            return None
    elif len(msg.position) >= 2:
        angles = (msg.position[0], msg.position[1])
    else:
        return None
    return angles if all(math.isfinite(a) for a in angles) else None


def _error_name(code: int) -> str:
    try:
        return ErrorCode(code).name
    except ValueError:
        return f'code {code}'


def _status_names(status: int) -> str:
    names = [flag.name for flag in Status if flag and status & flag]
    return ', '.join(names) or 'ok'


def main(args: list[str] | None = None) -> None:
    """Run the bridge until SIGINT/SIGTERM; the port is closed and its thread joined."""
    run_node(BridgeNode, args)
