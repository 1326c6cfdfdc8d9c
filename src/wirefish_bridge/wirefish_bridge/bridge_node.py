# SPDX-License-Identifier: Apache-2.0
"""
bridge_node: the serial link to the fish's board (STM32F407, §2.1), see PROTOCOL.md.

Drive modes (``drive_mode``, see ``bridge_node_parameters.DriveMode``): ``stream`` forwards
servo_cmd; ``gait`` sends the CPG node's parameters and the board integrates eq 1 itself.
Subscribes
    ``servo_cmd`` (sensor_msgs/JointState ``servo_1``, ``servo_2``, rad; sensor-data QoS, as the
    CPG publishes it): stream mode forwards it as SERVO_CMD frames, at most
    ``max_command_rate_hz``; when it stops for ``command_timeout_s`` (or before the first one)
    the bridge commands neutral. Gait mode compares it with the board's servo angles
    (``gait_link.OscillatorWatch``: a divergence beyond ``divergence_bound_rad`` warns).
    ``cpg_params`` (wirefish_msgs/CpgParams, latched): gait mode sends each change as a GAIT
    with the next gait id, again every ``gait_resend_s`` until an ACK or the telemetry's gait id
    acknowledges it (``gait_link.GaitLink``).
LINK_CONFIG (telemetry period and form, HEALTH period, link timeout, coast time: the
parameters of the same names) goes out when the fish identifies itself, again until an ACK
accepts it, in gait mode or whenever it differs from the fish's boot defaults; until that ACK
neither a GAIT nor a SERVO_CMD goes out (the fish rests on its failsafe meanwhile).
Publishes (sensor-data QoS, stamped on receipt with the node clock; on simulated time neither
these nor a SERVO_CMD before the node has heard the graph's clock)
    ``imu/data`` (sensor_msgs/Imu, frame ``imu_frame_id``), ``attitude``
    (geometry_msgs/Vector3Stamped: roll, pitch, yaw rad), ``servo_state`` (sensor_msgs/JointState,
    the servo angles the fish reports: the board's commanded angle after its clamp, the
    virtual fish's modelled reel angle), ``battery`` (sensor_msgs/BatteryState, at
    ``battery_rate_hz`` of the board's own clock, and at once when the low-battery flag
    changes); and ``/diagnostics``
    (diagnostic_msgs/DiagnosticArray, reliable) at ``diagnostics_rate_hz``: one status named
    ``<namespace>/bridge_node: serial link <port>``, hardware_id ``<node> on <port> (<device>)``.
Servo calibration (``servo_trim_link``): the services ``servo_trim``
(wirefish_msgs/ServoTrim: one SERVO_TRIM, judged here first, resent until the fish answers) and
``servo_sweep`` (wirefish_msgs/ServoSweep: the wiring check, stream mode only), and the latched
``servo_calibration`` (wirefish_msgs/ServoCalibration: both servos' last SERVO_TRIM_REPORT; the
bridge READs both at link-up). The services wait for the fish, so they are served by a second
node, ``<name>_calibration``, spun on a thread of its own: the wait never holds up servo_cmd,
heartbeats or the command tick (a coroutine callback would, on the events executor, not run).
Only the fish it was started for: a virtual fish's link whose owner record says it is stale,
or a device that is some process's controlling terminal, is not opened (``link_owner``); the
port is locked (a second bridge on it cannot open it and keeps retrying); nothing is written to
it until the device has sent a fish HEARTBEAT (a device silent for ``fish_identify_timeout_s``
is closed and reopened: a stale link may point at an unrelated terminal). Telemetry outside
the physical limits of ``telemetry_limits`` is counted (``telemetry_rejected``) and dropped,
never published.
The port is read by the transport's thread. Telemetry is published straight from that thread
(publishing is thread-safe): the 100 Hz path then costs no executor wake-up, which was the larger
part of the bridge's CPU and of the bytes -> imu/data latency. Every other frame and link event
goes into an inbox that the executor drains: the reader hands it over with ``create_task`` on
the node's executor (one task pending at most; the events executor has no guard conditions,
and this works on both), and each diagnostics tick drains it too (events from before the node
was spun), so the executor never waits on the device. An unplugged device is reopened by the
transport with backoff; the node keeps running.
"""

from __future__ import annotations

from collections import deque
import math
import os
import threading
import time

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Vector3Stamped
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.timer import Timer
from sensor_msgs.msg import BatteryState, Imu, JointState

from wirefish_bridge.bridge_node_parameters import (DriveMode, link_config,
                                                    LINK_CONFIG_PARAMETERS, LINK_PARAMETERS,
                                                    TABLE)
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.command_gate import CommandGate, NEUTRAL
from wirefish_bridge.gait_link import ConfigLink, GaitLink, GaitParameters, OscillatorWatch
from wirefish_bridge.graph_clock import GraphTime
from wirefish_bridge.link_health import identifies_fish, Level, LinkHealth
from wirefish_bridge.link_owner import open_refusal
from wirefish_bridge.protocol import (Ack, ErrorReport, Health, Heartbeat, LinkConfig,
                                      MsgType, PROTOCOL_VERSION, ProtocolMessage, Role,
                                      ServoCommand, SERVOS, ServoTrim as ServoTrimFrame,
                                      ServoTrimReport, Status, Telemetry, telemetry_of,
                                      TelemetryCompact, TrimOp)
from wirefish_bridge.ros_messages import (attitude_message, battery_message,
                                          diagnostic_status, imu_message, servo_state_message)
from wirefish_bridge.servo_trim_link import (CalibrationState, gait_mode_hint, Outcome,
                                             ServoSweep, sweep_problem, trim_request,
                                             TrimExchange)
from wirefish_bridge.transport import (LinkDown, LinkState, LinkWriteError, PeerNotIdentified,
                                       SerialLink)
from wirefish_common.cdr_views import CdrError, read_joint_state
from wirefish_common.decimator import Decimator
from wirefish_common.frames import declare_frame_prefix, prefixed
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import LATCHED, RELIABLE, SENSOR_DATA
from wirefish_common.servo_joints import JointProblem, servo_angles
from wirefish_msgs.msg import CpgParams, ServoCalibration, ServoTrimReport as ReportMsg
from wirefish_msgs.srv import ServoSweep as ServoSweepSrv, ServoTrim as ServoTrimSrv


# Rate of the command tick (Hz): the failsafe and held commands (see _make_timers).
COMMAND_TICK_HZ = 20.0
# Gait mode: a gait change waiting longer than this for the fish's acknowledgement is a WARN (s).
# rf433's round trip is 0.2-0.4 s and a GAIT is resent every gait_resend_s (0.4 s): twice the
# slowest of a working link.
UNACKNOWLEDGED_WARN_S = 1.0
# servo_trim: how long a call waits for the fish's answer (s); a copy goes every gait_resend_s.
SERVO_TRIM_TIMEOUT_S = 2.0
# At link-up the bridge READs each servo's calibration this many times at most (every
# gait_resend_s) until its report comes: a firmware without SERVO_TRIM is not asked forever.
CALIBRATION_READS = 3


def report_message(report: ServoTrimReport | None) -> ReportMsg:
    """Return the ROS form of a SERVO_TRIM_REPORT (servo 0: none)."""
    if report is None:
        return ReportMsg()
    return ReportMsg(servo=report.servo, source=int(report.source), direction=report.direction,
                     neutral_us=report.neutral_us, us_per_rad=report.us_per_rad,
                     min_us=report.min_us, max_us=report.max_us)


class BridgeNode(Node):
    """Wires servo_cmd to the serial link and the fish's telemetry to ROS topics."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, wire topics and timers, start the serial link."""
        super().__init__('bridge_node', **kwargs)
        self._node_parameters = NodeParameters(self, TABLE, self._apply)
        self._frame_prefix = declare_frame_prefix(self)  # fish_1 -> fish_1/imu_link
        self._values = self._node_parameters.values  # live: a set is in it before _apply
        self._started = time.monotonic()  # the host's uptime in its HEARTBEAT: a process age
        self._graph_time = GraphTime()
        self._encoder = FrameEncoder()
        self._decoder = StreamDecoder()
        self._gate = CommandGate(self._values['max_command_rate_hz'],
                                 self._values['command_timeout_s'],
                                 self._values['servo_limit_rad'])
        self._inbox: deque = deque(maxlen=1000)  # reader thread -> executor; bounded
        self._inbox_lock = threading.Lock()
        self._drain_scheduled = False  # a drain task is pending on the executor (inbox lock)
        self._health = LinkHealth(self._values['heartbeat_timeout_s'], self._now_s())
        self._battery_rate = Decimator(self._values['battery_rate_hz'])
        # Gait mode's state: the executor sets and sends, the reader thread reports what the
        # board runs; one lock between them.
        self._gait_lock = threading.Lock()
        self._gait = GaitLink(self._values['gait_resend_s'], self._values['gait_min_interval_s'],
                              self._values['gait_repeat_s'])
        self._config = ConfigLink(link_config(self._values), self._values['gait_resend_s'])
        self._watch = OscillatorWatch(self._values['divergence_window_s'],
                                      self._values['divergence_bound_rad'])
        # Servo calibration: the reader thread takes the answers, the service thread waits on
        # them (the condition), the executor sends the sweep and the link-up READs.
        self._send_lock = threading.Lock()   # the encoder's seq and the link: two senders
        self._trim_cond = threading.Condition()
        self._trim: TrimExchange | None = None
        self._calibration = CalibrationState()
        self._reads_left = {servo: 0 for servo in SERVOS}
        self._last_read_s = -math.inf
        self._sweep: ServoSweep | None = None

        self._imu_pub = self.create_publisher(Imu, 'imu/data', SENSOR_DATA)
        self._attitude_pub = self.create_publisher(Vector3Stamped, 'attitude',
                                                   SENSOR_DATA)
        self._servo_pub = self.create_publisher(JointState, 'servo_state',
                                                SENSOR_DATA)
        self._battery_pub = self.create_publisher(BatteryState, 'battery',
                                                  SENSOR_DATA)
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', RELIABLE)
        self._calibration_pub = self.create_publisher(ServoCalibration, 'servo_calibration',
                                                      LATCHED)
        # Raw: the pair is read from the bytes (cdr_views), no Python message is built.
        self.create_subscription(JointState, 'servo_cmd', self._on_servo_cmd,
                                 SENSOR_DATA, raw=True)
        self.create_subscription(CpgParams, 'cpg_params', self._on_cpg_params, LATCHED)
        self._bridge_timers: dict[str, Timer] = {}
        self._make_timers()
        self._link = self._make_link()
        self._link.start()
        self._start_calibration_services()

    # --- servo calibration services (their own node and thread) -----------------------------
    def _start_calibration_services(self) -> None:
        # No global arguments: the process's node-name remap would name it bridge_node too.
        self._service_node = Node(f'{self.get_name()}_calibration',
                                  namespace=self.get_namespace(), context=self.context,
                                  use_global_arguments=False, start_parameter_services=False)
        self._service_node.create_service(ServoTrimSrv, 'servo_trim', self._on_servo_trim)
        self._service_node.create_service(ServoSweepSrv, 'servo_sweep', self._on_servo_sweep)
        self._service_executor = SingleThreadedExecutor(context=self.context)
        self._service_executor.add_node(self._service_node)
        self._services_stop = threading.Event()
        self._service_thread = threading.Thread(target=self._spin_services,
                                                name='calibration services', daemon=True)
        self._service_thread.start()

    def _spin_services(self) -> None:
        try:
            while not self._services_stop.is_set() and self.context.ok():
                self._service_executor.spin_once(timeout_sec=0.1)
        except (ExternalShutdownException, RuntimeError):
            pass   # the context went down under the loop: the process is stopping

    def _on_servo_trim(self, request, response):
        """Send one SERVO_TRIM and wait for the fish's answer (the service thread)."""
        frame, why = trim_request(request.servo, request.op, request.direction,
                                  request.neutral_us, request.us_per_rad)
        known = self._calibration.reports.get(request.servo)
        response.calibration = report_message(known)
        if frame is None:
            response.accepted, response.reason = False, why
            return response
        # One call at a time: the services' executor is single-threaded, a second call waits.
        with self._trim_cond:
            exchange = self._trim = TrimExchange(frame, time.monotonic(),
                                                 self._values['gait_resend_s'],
                                                 SERVO_TRIM_TIMEOUT_S)
            try:
                while True:
                    now = time.monotonic()
                    due = exchange.due(now)
                    if exchange.done:
                        break
                    if due:   # sent under the condition: its ACK cannot overtake its seq
                        seq = self._send(frame)
                        if seq is not None:
                            exchange.sent(seq, now)
                    self._trim_cond.wait(timeout=0.05)
            finally:
                self._trim = None
        response.accepted = exchange.outcome is Outcome.ACCEPTED
        response.reason = exchange.reason(self.get_fully_qualified_name())
        if exchange.report is not None:
            response.calibration = report_message(exchange.report)
        level = self.get_logger().info if response.accepted else self.get_logger().warn
        level(f'servo_trim servo {frame.servo} {TrimOp(frame.op).name}: '
              + ('accepted' if response.accepted else response.reason))
        return response

    def _on_servo_sweep(self, request, response):
        """Start (or with amplitude 0 stop) a wiring sweep (the service thread)."""
        if request.amplitude_rad == 0.0:
            with self._trim_cond:
                self._sweep = None
            response.accepted, response.reason = True, ''
            return response
        if self._gait_mode:
            response.accepted = False
            response.reason = ('the bridge is in gait mode: the board runs the gait and takes '
                               'no SERVO_CMD of a sweep; '
                               + gait_mode_hint(self.get_fully_qualified_name()))
            return response
        problem = sweep_problem(request.servo, request.amplitude_rad, request.period_s,
                                self._values['servo_limit_rad'])
        now = time.monotonic()
        with self._trim_cond:
            running = self._sweep
            if problem is None and running is not None and not running.over(now):
                problem = (f'a sweep of servo {running.servo} runs for another '
                           f'{running.start_s + running.period_s - now:.1f} s (amplitude 0 '
                           'stops it)')
            if problem is None:
                self._sweep = ServoSweep(request.servo, float(request.amplitude_rad),
                                         float(request.period_s), now)
        response.accepted, response.reason = problem is None, problem or ''
        if problem is None:
            self.get_logger().info(f'servo_sweep: servo {request.servo} 0 -> '
                                   f'+{request.amplitude_rad:g} -> -{request.amplitude_rad:g} '
                                   f'-> 0 rad over {request.period_s:g} s; servo_cmd ignored '
                                   'meanwhile')
        return response

    def _sweep_command(self) -> tuple[float, float] | None:
        """Return the sweep's SERVO_CMD angles of now, or None when no sweep runs."""
        with self._trim_cond:
            sweep = self._sweep
            if sweep is None:
                return None
            now = time.monotonic()
            if sweep.over(now):
                self._sweep = None
                self.get_logger().info(f'servo_sweep of servo {sweep.servo} done: forwarding '
                                       'servo_cmd again')
                return NEUTRAL
            return sweep.command(now)

    def _on_trim_answer(self, message: Ack | ServoTrimReport) -> None:
        """Take a SERVO_TRIM's ACK or a report (the reader thread); wake the waiting call."""
        with self._trim_cond:
            if isinstance(message, Ack):
                if self._trim is not None:
                    self._trim.on_ack(message)
            else:
                if self._trim is not None:
                    self._trim.on_report(message)
                if self._calibration.on_report(message):
                    self._reads_left[message.servo] = 0
                    reports = dict(self._calibration.reports)
                    state = ServoCalibration(servo_1=report_message(reports[1]),
                                             servo_2=report_message(reports[2]))
                    state.header.stamp = self.get_clock().now().to_msg()
                    self._calibration_pub.publish(state)
            self._trim_cond.notify_all()

    def _send_calibration_reads(self) -> None:
        """READ each servo not reported since link-up (at most CALIBRATION_READS times)."""
        now = time.monotonic()
        with self._trim_cond:
            servos = [servo for servo, left in self._reads_left.items() if left > 0]
            if not servos or now - self._last_read_s < self._values['gait_resend_s']:
                return
            self._last_read_s = now
            for servo in servos:
                if self._send(ServoTrimFrame(servo, TrimOp.READ)) is not None:
                    self._reads_left[servo] -= 1

    # --- parameters -------------------------------------------------------------------------
    def _apply(self, names: frozenset[str]) -> None:
        self._gate.max_rate_hz = self._values['max_command_rate_hz']
        self._gate.timeout_s = self._values['command_timeout_s']
        self._gate.limit_rad = self._values['servo_limit_rad']
        self._health.heartbeat_timeout_s = self._values['heartbeat_timeout_s']
        self._battery_rate.rate_hz = self._values['battery_rate_hz']
        with self._gait_lock:
            self._gait.resend_s = self._values['gait_resend_s']
            self._gait.min_interval_s = self._values['gait_min_interval_s']
            self._gait.repeat_s = self._values['gait_repeat_s']
            self._config.resend_s = self._values['gait_resend_s']
            self._watch.window_s = self._values['divergence_window_s']
            self._watch.bound_rad = self._values['divergence_bound_rad']
            if names & LINK_CONFIG_PARAMETERS:
                self._config.set_config(link_config(self._values), self._now_s())
        if 'drive_mode' in names:
            self.get_logger().info(f'drive mode {self._values["drive_mode"]}')
            if self._gait_mode:
                with self._trim_cond:
                    self._sweep = None   # the board runs the gait: no SERVO_CMD of ours
            self._on_command_tick()   # gait mode: the current gait goes out now
        if names & {'heartbeat_rate_hz', 'diagnostics_rate_hz'}:
            self._make_timers()
        if names & LINK_PARAMETERS:
            self._link.stop()
            self._link = self._make_link()
            self._link.start()

    def _make_timers(self) -> None:
        for timer in self._bridge_timers.values():
            self.destroy_timer(timer)
        # The command tick runs the failsafe (neutral within 50 ms of command_timeout_s) and
        # sends a held command that no newer one superseded. It need not run at the rate limit
        # (100 wake-ups a second): a held command also leaves with the next one that arrives.
        self._bridge_timers = {
            'command': self.create_timer(1.0 / COMMAND_TICK_HZ, self._on_command_tick),
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
                          backoff_max_s=self._values['reconnect_backoff_max_s'],
                          identify_timeout_s=self._values['fish_identify_timeout_s'],
                          open_check=open_refusal)

    # --- reader thread side: decode, publish telemetry, hand the rest over ------------------
    def _on_bytes(self, chunk: bytes) -> None:
        others = []
        for frame in self._decoder.feed(chunk):
            if identifies_fish(frame.message):
                # Here, on the reader thread: the heartbeat came from the device now open.
                self._link.identify_peer()
            if isinstance(frame.message, (Telemetry, TelemetryCompact)):
                self._publish_from_reader(frame.message)
            elif isinstance(frame.message, ServoTrimReport) or (
                    isinstance(frame.message, Ack)
                    and frame.message.acked_type == MsgType.SERVO_TRIM):
                self._on_trim_answer(frame.message)
            else:
                others.append(frame)
        if others:
            with self._inbox_lock:
                self._inbox.extend(others)
            self._hand_over()

    def _publish_from_reader(self, message: Telemetry | TelemetryCompact) -> None:
        problem = self._health.on_telemetry(message, self._now_s())
        if problem is not None:
            self.get_logger().warn(f'impossible telemetry dropped: {problem}',
                                   throttle_duration_sec=2.0)
            return
        telemetry = telemetry_of(message)   # either form, in SI units
        assert telemetry is not None
        now = self._now_s()
        with self._gait_lock:
            self._gait.on_telemetry(telemetry.gait_id, now)
            if telemetry.status & Status.GAIT_MODE:
                self._watch.add_board(now, (telemetry.servo_1, telemetry.servo_2))
        try:
            self._publish_telemetry(telemetry)
        except Exception as error:  # noqa: B902 (the reader thread must survive; say why)
            if self.context.ok():  # after shutdown (Ctrl-C) there is nothing to say
                self.get_logger().error(f'telemetry not published: {error!r}',
                                        throttle_duration_sec=2.0)

    def _on_link_state(self, state: LinkState, detail: str) -> None:
        if state is LinkState.IDENTIFYING:   # a new open: maybe another device
            self._decoder.reset_sequence()
            self._health.on_new_device()
        with self._inbox_lock:
            self._inbox.append((state, detail))
        self._hand_over()

    def _hand_over(self) -> None:
        """Have the executor drain the inbox soon: one pending drain task at most."""
        with self._inbox_lock:
            executor = self.executor
            if self._drain_scheduled or executor is None:  # None: not spun yet (see module doc)
                return
            self._drain_scheduled = True
        executor.create_task(self._drain_inbox)

    # --- executor side ----------------------------------------------------------------------
    def _drain_inbox(self) -> None:
        with self._inbox_lock:
            items = list(self._inbox)
            self._inbox.clear()
            self._drain_scheduled = False
        for item in items:
            if isinstance(item, tuple):
                state, detail = item
                if state is LinkState.CONNECTED:
                    self.get_logger().info(f'link {state.value}: {detail}')
                    self._reconfigure_fish()   # another board, or the same one reset
                else:
                    self.get_logger().warn(f'link {state.value}: {detail}')
                continue
            message = item.message
            if identifies_fish(message):
                restarts = self._health.fish_restarts
                self._log(self._health.on_heartbeat(message, self._now_s()))
                if self._health.fish_restarts != restarts:   # its uptime went back
                    self.get_logger().warn('the fish restarted: configuring it again')
                    self._reconfigure_fish()
            elif isinstance(message, Ack):
                with self._gait_lock:
                    self._gait.on_ack(message, self._now_s())
                    configured = self._config.on_ack(message)
                    if configured:
                        self._gait.waits_from(self._now_s())
                if configured:
                    self._send_gait_mode_frames()   # the gait it held back
            elif isinstance(message, Health):
                line = self._health.on_health(message)
                if line is not None:
                    self.get_logger().error(line)
            elif isinstance(message, ErrorReport):
                self.get_logger().warn(self._health.on_error_report(message),
                                       throttle_duration_sec=2.0)

    def _log(self, entry: tuple[Level, str] | None) -> None:
        if entry is not None:
            level, text = entry
            log = self.get_logger()
            (log.error if level is Level.ERROR else log.info)(text)

    def _on_the_graphs_clock(self) -> bool:
        """
        Return False on simulated time until this node has heard the graph's clock.

        Until then its timers do not run, the heartbeat among them, so the fish holds neutral
        on its heartbeat failsafe: a SERVO_CMD relayed meanwhile would step the lockstep clock
        with a command the fish ignores (at --speed max 6 s of simulated time went so), and a
        telemetry sample would be stamped 0, placed nowhere.
        """
        return self.get_clock().now().nanoseconds != 0

    def _publish_telemetry(self, telemetry: Telemetry) -> None:
        if not self._on_the_graphs_clock():
            return
        stamp = self.get_clock().now().to_msg()
        frame_id = prefixed(self._frame_prefix, self._values['imu_frame_id'])
        tilt = self._values['orientation_stddev_rad']
        self._imu_pub.publish(imu_message(
            telemetry, stamp, frame_id, (tilt, tilt, self._values['yaw_stddev_rad']),
            self._values['angular_velocity_stddev_rad_s'],
            self._values['linear_acceleration_stddev_m_s2']))
        self._attitude_pub.publish(attitude_message(telemetry, stamp, frame_id))
        self._servo_pub.publish(servo_state_message(telemetry, stamp))
        low_battery = bool(telemetry.status & Status.LOW_BATTERY)
        # Decimated on the board's clock, which advances one telemetry period per frame: the
        # node clock at a frame's receipt does not when frames come in a burst (a radio, a
        # clock at --speed max whose steps outrun the bridge: 9.4 Hz of 10 in simulated time).
        if self._battery_rate.due(telemetry.board_time_ms * 1e-3, low_battery):
            self._battery_pub.publish(battery_message(
                telemetry, stamp, low_battery, prefixed(self._frame_prefix, 'base_link')))

    def _now_s(self) -> float:
        """Return the graph's time (s, never back: ``GraphTime``) from the node clock."""
        return self._graph_time(self.get_clock().now().nanoseconds * 1e-9)

    @property
    def _gait_mode(self) -> bool:
        return self._values['drive_mode'] == DriveMode.GAIT

    def _on_servo_cmd(self, data: bytes) -> None:
        try:
            angles = servo_angles(read_joint_state(data))
        except CdrError as error:
            angles = JointProblem('bytes', str(error))
        if isinstance(angles, JointProblem):
            self.get_logger().warn(f'servo_cmd ignored: {angles.message}',
                                   throttle_duration_sec=2.0)
            return
        if self._gait_mode:   # the board runs the gait itself: compare, never forward
            with self._gait_lock:
                self._watch.add_host(self._now_s(), angles)
            return
        if not self._streams() or not self._on_the_graphs_clock():
            return
        sweep = self._sweep_command()
        if sweep is not None:   # the wiring sweep's angles go instead (at servo_cmd's pace)
            angles = sweep
        # The gate counts the wire's time, not the graph's: its rate limit is about the serial
        # link, and on the lockstep road a command that came before this node heard its step's
        # /clock found no credit on the graph's clock and was held for the next tick, which
        # waits on simulated time, which waits on that very command.
        to_send = self._gate.on_command(angles, time.monotonic())
        if to_send is not None:
            self._send(ServoCommand(*to_send))

    def _on_cpg_params(self, msg: CpgParams) -> None:
        parameters = GaitParameters(
            float(msg.frequency_hz), (float(msg.amplitude[0]), float(msg.amplitude[1])),
            (float(msg.offset[0]), float(msg.offset[1])), float(msg.w12), float(msg.w21),
            float(msg.phi12), float(msg.phi21), float(msg.alpha))
        with self._gait_lock:
            new = self._gait.set_gait(parameters, self._now_s())
        if new:
            self._send_gait_mode_frames()

    def _reconfigure_fish(self) -> None:
        """Make LINK_CONFIG, the current gait and the calibration READs due."""
        with self._gait_lock:
            self._config.link_up(self._now_s())
            self._gait.on_fish_restart()
        with self._trim_cond:
            self._reads_left = {servo: CALIBRATION_READS for servo in SERVOS}
            self._last_read_s = -math.inf
        self._send_gait_mode_frames()
        self._send_calibration_reads()

    def _send_gait_mode_frames(self) -> None:
        """Send a LINK_CONFIG and a GAIT that are due (the gait in gait mode only)."""
        now = self._now_s()
        with self._gait_lock:
            config = self._config.due(now) if self._configures_fish() else None
            # GAIT once the fish runs the configured link: at its boot defaults (100 Hz of
            # full telemetry) a board floods a narrow radio, and an ACK finds no room.
            gait = self._gait.due(now) if self._gait_mode and self._link_configured() else None
        if config is not None:
            seq = self._send(config)
            if seq is not None:
                with self._gait_lock:
                    self._config.sent(seq, now)
        if gait is not None:
            seq = self._send(gait)
            if seq is not None:
                with self._gait_lock:
                    self._gait.sent(seq, now)

    def _streams(self) -> bool:
        """
        Return True when SERVO_CMD may go out (stream mode): once the fish runs the link.

        A stream of 100 Hz fills a narrow radio (rf433: 174 % of its UART towards the fish),
        and whole frames that find the queue full are refused: the LINK_CONFIG and the
        heartbeats among them were refused for a minute on end. Until the fish acknowledges
        the link it rests on its own failsafe, as a fish in gait mode before its first GAIT.
        """
        with self._gait_lock:
            return self._link_configured()

    def _link_configured(self) -> bool:
        """Return True when the fish runs the link the bridge wants (the gait lock held)."""
        return self._config.acknowledged or not self._configures_fish()

    def _configures_fish(self) -> bool:
        """Return True when LINK_CONFIG must go out: gait mode, or not the boot defaults."""
        return self._gait_mode or self._config.config != LinkConfig()

    def _gait_problem(self, now: float) -> str | None:
        """Return what gait mode finds wrong for /diagnostics, or None (the gait lock held)."""
        gait = self._gait
        if gait.parameters is None:
            return 'gait mode: no cpg_params yet'
        if gait.refusal is not None:
            return f'the fish refused gait {gait.gait_id} (error {gait.refusal})'
        waiting = gait.waiting_s(now)
        if waiting > UNACKNOWLEDGED_WARN_S:   # one in flight is normal: a radio's round trip
            return f'the fish has acknowledged no gait for {waiting:.1f} s (gait {gait.gait_id})'
        if self._config.refusal is not None:
            return f'the fish refused LINK_CONFIG (error {self._config.refusal})'
        return self._watch.problem(now)

    def _mode_values(self) -> dict[str, object]:
        """Return the /diagnostics values of the drive mode (the gait lock held)."""
        values: dict[str, object] = {'drive_mode': self._values['drive_mode'],
                                     'link_config_acknowledged': self._config.acknowledged,
                                     'link_configured': self._link_configured()}
        if self._gait_mode:
            values.update(self._gait.values())
            divergence = self._watch.divergence(self._now_s())
            values['oscillator_divergence_rad'] = (math.nan if divergence is None
                                                   else divergence)
        return values

    def _on_command_tick(self) -> None:
        self._send_gait_mode_frames()
        self._send_calibration_reads()
        if self._gait_mode or not self._streams():
            return   # no SERVO_CMD: one would put the board back in stream mode
        sweep = self._sweep_command()
        if sweep is not None:
            to_send = self._gate.on_command(sweep, time.monotonic())
            if to_send is not None:
                self._send(ServoCommand(*to_send))
            return
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

    def _send(self, message: ProtocolMessage) -> int | None:
        """Send ``message``; return its sequence number, or None when it did not go out."""
        with self._send_lock:   # the executor and the calibration services' thread
            seq = self._encoder.next_seq
            frame = self._encoder.encode(message)
            try:
                self._link.write(frame)
            except PeerNotIdentified:
                return None   # not a fish (yet): counted by the link as withheld
            except (LinkDown, LinkWriteError):
                self._health.out.dropped += 1  # the link's state is in /diagnostics
                return None
            self._health.out.sent += 1
            return seq

    def _publish_diagnostics(self) -> None:
        self._drain_inbox()  # heartbeats first, so the status is up to date
        now = self._now_s()
        port, state, stats = self._values['port'], self._link.state, self._link.stats
        with self._gait_lock:
            problem = self._gait_problem(now) if self._gait_mode else None
            mode_values = self._mode_values()
        level, message = self._health.level(now, state, port, stats,
                                            self._gate.failsafe and not self._gait_mode,
                                            problem)
        values = self._health.values(now, state, port, self._decoder.stats, stats,
                                     self._gate.counters())
        values.update(mode_values)
        node = self.get_fully_qualified_name()
        device = os.path.realpath(port)
        hardware_id = f'{node} on {port}' + (f' ({device})' if device != port else '')
        array = DiagnosticArray()
        array.header.stamp = self.get_clock().now().to_msg()
        array.status = [diagnostic_status(f'{node}: serial link {port}', hardware_id, level,
                                          message, values)]
        self._diag_pub.publish(array)

    def destroy_node(self) -> None:
        """Command neutral, stop the serial link (joins its thread, closes the port), the node."""
        if self._gait_mode:
            # Rest through the oscillator (amplitudes and offsets to 0 at alpha): no step.
            with self._gait_lock:
                rest = self._gait.resting_gait()
            if rest is not None:
                self._send(rest)
        else:
            # The fish would otherwise hold the last angle until its own command timeout.
            self._send(ServoCommand(*NEUTRAL))
        self._services_stop.set()
        self._service_thread.join(timeout=2.0)
        self._service_executor.shutdown(timeout_sec=1.0)
        self._service_node.destroy_node()
        self._link.stop()
        super().destroy_node()


def main(args: list[str] | None = None) -> None:
    """Run the bridge until SIGINT/SIGTERM; the port is closed and its thread joined."""
    run_node(BridgeNode, args)
