"""
kinematics_node: the tail's body wave and swimming-speed estimate from the servo angles.

Subscribes
    ``servo_cmd`` (sensor_msgs/JointState, sensor-data QoS; joints ``servo_1``, ``servo_2`` in
    any order, position rad, velocity rad/s optional), or the measured ``servo_state`` when
    ``use_servo_state`` is true. Samples with NaN/inf values or without both joints are dropped
    with a throttled warning. Times are the header stamps (node clock if unstamped).
    ``target_wave`` (wirefish_msgs/BodyWaveSpec, reliable, transient local): the desired wave;
    the latest of it and the ``wave_*`` parameters wins.
Publishes (frame ``tail_base`` = C0 of paper section 3.1)
    ``body_wave`` (wirefish_msgs/BodyWave, sensor data) at ``publish_rate_hz`` when a new
    sample arrived: ``station_count`` stations, eqs 2-15; ``y_desired`` (eq 23) once the tail
    beats, shown at the tail's phase (see ``desired_wave.wave_time_at_phase``).
    ``body_wave_markers`` (visualization_msgs/MarkerArray, reliable depth 5, so RViz's default
    subscription matches): tail polyline, desired
    wave as dots, link ends O1 (sphere) and O2 (cube).
    ``speed_estimate`` (wirefish_msgs/SpeedEstimate, reliable) once per completed tail beat
    (stamped at the end of the period), eqs 16-22; all zeros while the tail is at rest.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from visualization_msgs.msg import Marker, MarkerArray
from wirefish_common.node_main import run_node
from wirefish_common.qos import LATCHED, RELIABLE, reliable, SENSOR_DATA
from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.desired_wave import desired_lateral_position, wave_time_at_phase
from wirefish_kinematics.geometry import GEOMETRY_FIELDS
from wirefish_kinematics.lighthill import SpeedEstimate, tail_tip_lateral_positions
from wirefish_kinematics.node_parameters import (declare, geometry_from, NODE_PARAMETERS,
                                                 SPECS, validate_update)
from wirefish_kinematics.servo_history import ServoHistory
from wirefish_kinematics.tail_beat import (estimate_speed_over, fundamental_phase,
                                           last_tail_beat, TailBeat)
from wirefish_kinematics.wire_coupling import bend_angles
from wirefish_msgs.msg import BodyWave, BodyWaveSpec, SpeedEstimate as SpeedEstimateMsg

FRAME = 'tail_base'
JOINTS = ('servo_1', 'servo_2')
MARKERS = reliable(depth=5)
# Below this half range (m) of the tip's lateral motion the tail counts as at rest.
REST_HALF_RANGE_M = 1e-4
WARN_PERIOD_S = 2.0
# The tail-beat search runs at most this often (s of sample time): an estimate is then at
# most this late, and the node does not re-scan its history at every body_wave.
DETECTION_PERIOD_S = 0.1


@dataclass(frozen=True)
class WaveTarget:
    """The desired wave of eq 23: c1 (m/m), c2 (1/m), k (rad/m), frequency (Hz)."""

    c1: float
    c2: float
    k: float
    frequency_hz: float


def wave_problem(msg: BodyWaveSpec) -> str | None:
    """Return why a BodyWaveSpec is unusable, or None."""
    values = (msg.c1, msg.c2, msg.k, msg.frequency_hz)
    if not all(math.isfinite(v) for v in values):
        return f'non-finite value in {values}'
    if msg.k <= 0.0 or not 0.0 < msg.frequency_hz <= 10.0:
        return f'need k > 0 and frequency_hz in (0, 10], got k={msg.k}, f={msg.frequency_hz}'
    return None


@dataclass(frozen=True)
class SampleProblem:
    """Why a JointState was dropped: a kind (throttled separately) and a message."""

    kind: str
    message: str


def servo_sample(msg: JointState
                 ) -> tuple[tuple[float, float], tuple[float, float]] | SampleProblem:
    """Return (angles, rates) of servo_1, servo_2 in a JointState, or why it is unusable."""
    names = list(msg.name)
    if not all(joint in names for joint in JOINTS):
        return SampleProblem('names', f'JointState needs joints {JOINTS}, got {names}')
    if len(msg.position) != len(names):
        return SampleProblem('size', f'JointState has {len(msg.position)} positions for '
                             f'{len(names)} names')
    index = [names.index(joint) for joint in JOINTS]
    angles = tuple(float(msg.position[i]) for i in index)
    if not all(math.isfinite(a) for a in angles):
        return SampleProblem('angles', f'non-finite servo angles {angles}')
    rates = (math.nan, math.nan)  # no velocities: eqs 21-22 use differences of the angles
    if len(msg.velocity) == len(names):
        rates = tuple(float(msg.velocity[i]) for i in index)
        if not all(math.isfinite(r) for r in rates):
            return SampleProblem('rates', f'non-finite servo rates {rates}')
    return angles, rates


def to_stamp(sec: int, nanosec: int) -> Time:
    """Return a builtin_interfaces/Time."""
    return Time(sec=int(sec), nanosec=int(nanosec))


class KinematicsNode(Node):
    """Computes the body wave and the Lighthill speed estimate from servo angles."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters; wire subscriptions, publishers and the publish timer."""
        super().__init__('kinematics_node', **kwargs)
        declare(self, NODE_PARAMETERS)
        self._values = {s.name: self.get_parameter(s.name).value for s in NODE_PARAMETERS}
        self._geometry = geometry_from(self._values)
        self._target = self._wave_from_parameters()
        self._history = ServoHistory(2.0 * self._values['max_tail_beat_period_s'])
        self._latest: tuple[int, int, tuple[float, float]] | None = None
        self._fresh = False
        # tail-beat state, reset with the history (_subscribe_servo)
        self._last_beat_end: float | None = None
        self._last_rest_t: float | None = None
        self._last_detection_t: float | None = None
        self._beat: TailBeat | None = None
        self._beat_phase = 0.0  # phase (rad) of y(q1)'s fundamental at the beat's start
        self._warned: dict[str, float] = {}
        self._body_pub = self.create_publisher(BodyWave, 'body_wave', SENSOR_DATA)
        # Reliable, unlike the data streams: RViz subscribes to markers reliably by default, and
        # a best-effort publisher would never match it. A reliable one matches both kinds.
        self._marker_pub = self.create_publisher(MarkerArray, 'body_wave_markers', MARKERS)
        self._speed_pub = self.create_publisher(SpeedEstimateMsg, 'speed_estimate', RELIABLE)
        self.create_subscription(BodyWaveSpec, 'target_wave', self._on_target, LATCHED)
        self._servo_sub = None
        self._subscribe_servo()
        self._timer = self.create_timer(1.0 / self._values['publish_rate_hz'], self._on_tick)
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)

    # --- parameters -----------------------------------------------------------------------
    def _wave_from_parameters(self) -> WaveTarget:
        v = self._values
        return WaveTarget(v['wave_c1'], v['wave_c2'], v['wave_k'], v['wave_frequency_hz'])

    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        # Every value, then the geometry they make together (its ValueError is the reason).
        return validate_update(SPECS, self._values, parameters, geometry_from)

    def _apply(self, parameters: list[Parameter]) -> None:
        names = {p.name for p in parameters if p.name in SPECS}
        for name in names:
            self._values[name] = self.get_parameter(name).value
        if names & set(GEOMETRY_FIELDS):
            self._geometry = geometry_from(self._values)
            self._fresh = self._latest is not None
            self._beat = None  # the overlay's phase is re-measured with the new geometry
        if names & {'wave_c1', 'wave_c2', 'wave_k', 'wave_frequency_hz'}:
            self._target = self._wave_from_parameters()
        if 'publish_rate_hz' in names:
            self.destroy_timer(self._timer)
            self._timer = self.create_timer(1.0 / self._values['publish_rate_hz'],
                                            self._on_tick)
        if 'max_tail_beat_period_s' in names:
            self._history.span_s = 2.0 * self._values['max_tail_beat_period_s']
        if 'use_servo_state' in names:
            self._subscribe_servo()

    def _subscribe_servo(self) -> None:
        if self._servo_sub is not None:
            self.destroy_subscription(self._servo_sub)
        topic = 'servo_state' if self._values['use_servo_state'] else 'servo_cmd'
        self._history.clear()
        self._latest, self._fresh = None, False
        self._last_beat_end = self._last_rest_t = self._last_detection_t = self._beat = None
        self._servo_sub = self.create_subscription(JointState, topic, self._on_servo,
                                                   SENSOR_DATA)

    # --- inputs ---------------------------------------------------------------------------
    def _on_servo(self, msg: JointState) -> None:
        sample = servo_sample(msg)
        if isinstance(sample, SampleProblem):
            # throttled per kind, so that one bad source cannot hide another
            now = self.get_clock().now().nanoseconds * 1e-9
            if now - self._warned.get(sample.kind, -math.inf) >= WARN_PERIOD_S:
                self._warned[sample.kind] = now
                self.get_logger().warn(f'{sample.message}; sample dropped')
            return
        sec, nanosec = msg.header.stamp.sec, msg.header.stamp.nanosec
        if sec == 0 and nanosec == 0:
            sec, nanosec = self.get_clock().now().seconds_nanoseconds()
        angles, rates = sample
        if self._history.add(sec, nanosec, angles, rates):
            self._latest, self._fresh = (sec, nanosec, angles), True

    def _on_target(self, msg: BodyWaveSpec) -> None:
        reason = wave_problem(msg)
        if reason is not None:
            self.get_logger().warn(f'target_wave ignored: {reason}')
            return
        self._target = WaveTarget(msg.c1, msg.c2, msg.k, msg.frequency_hz)

    # --- outputs --------------------------------------------------------------------------
    def _on_tick(self) -> None:
        if not self._fresh:
            return
        self._fresh = False
        sec, nanosec, angles = self._latest
        stamp = to_stamp(sec, nanosec)
        g = self._geometry
        stations = np.linspace(0.0, g.tail_length, self._values['station_count'])
        beta1, beta2 = (float(b) for b in bend_angles(angles[0], angles[1], g))
        x, y = body_positions(stations, beta1, beta2, g)
        theta1, theta2 = swing_angles(beta1, beta2, g)
        t = self._history.last_time()
        last = self._last_detection_t
        if last is None or not 0.0 <= t - last < DETECTION_PERIOD_S:  # also after a jump back
            self._last_detection_t = t
            self._update_tail_beat()
        y_desired = self._desired_wave(t, stations)
        msg = BodyWave(q=stations.tolist(), x=x.tolist(), y=y.tolist(),
                       y_desired=[] if y_desired is None else y_desired.tolist(),
                       beta1=beta1, beta2=beta2, theta1=float(theta1), theta2=float(theta2))
        msg.header.stamp, msg.header.frame_id = stamp, FRAME
        self._body_pub.publish(msg)
        ends_x, ends_y = body_positions(np.array(g.link_end_stations), beta1, beta2, g)
        self._marker_pub.publish(self._markers(stamp, x, y, stations, y_desired,
                                               ends_x, ends_y))

    def _update_tail_beat(self) -> None:
        """Find the last full tail beat; publish an estimate per new one (or one at rest)."""
        g = self._geometry
        times, angles, rates = self._history.arrays()
        y_tip = tail_tip_lateral_positions(angles, g)
        beat = last_tail_beat(times, y_tip, REST_HALF_RANGE_M)
        if beat is None:
            self._beat = None
            at_rest = 0.5 * np.ptp(y_tip) < REST_HALF_RANGE_M
            span = self._values['max_tail_beat_period_s']
            if (at_rest and self._history.duration_s() >= span
                    and (self._last_rest_t is None or times[-1] - self._last_rest_t >= span)):
                self._last_rest_t = float(times[-1])
                self._publish_speed(SpeedEstimate(0.0, 0.0, 0.0, 0.0, 0.0, 0.5 * np.ptp(y_tip)),
                                    float(times[-1]))
            return
        # The crossings move by a few ms as the history's range slides (they are interpolated
        # at its middle): the same beat found again is not a new one.
        if self._last_beat_end is None or beat.end - self._last_beat_end > 0.5 * beat.period:
            self._last_beat_end = beat.end
            self._publish_speed(estimate_speed_over(times, angles, rates, beat.start, beat.end,
                                                    g), beat.end)
        if self._beat is None or self._beat.end != beat.end:
            # the overlay's phase: that of y(q1) over this beat (paper eq 25 aligns at O1)
            beta1, beta2 = bend_angles(angles[:, 0], angles[:, 1], g)
            _, y_q1 = body_positions(np.array([g.l1]), beta1, beta2, g)
            self._beat = beat
            self._beat_phase = float(fundamental_phase(times, y_q1[:, 0], beat, beat.start))

    def _desired_wave(self, t: float, stations: np.ndarray) -> np.ndarray | None:
        """Return y_body at the stations, shown at the tail's phase at t; None if unknown."""
        if self._beat is None:
            return None
        target, q1 = self._target, self._geometry.l1
        phase = self._beat_phase + 2.0 * math.pi * (t - self._beat.start) / self._beat.period
        if target.c1 * q1 + target.c2 * q1 * q1 < 0.0:  # a negative envelope flips the sign
            phase += math.pi
        tau = wave_time_at_phase(phase, q1, target.k, target.frequency_hz)
        return desired_lateral_position(stations, tau, target.c1, target.c2, target.k,
                                        target.frequency_hz)

    def _publish_speed(self, estimate: SpeedEstimate, t: float) -> None:
        msg = SpeedEstimateMsg(speed=estimate.speed, thrust=estimate.thrust,
                               drag=estimate.drag, swimming_number=estimate.swimming_number,
                               tail_beat_hz=estimate.tail_beat_hz,
                               tail_tip_amplitude=float(estimate.tail_tip_amplitude))
        msg.header.stamp = to_stamp(*self._history.stamp_of(t))
        msg.header.frame_id = FRAME
        self._speed_pub.publish(msg)

    def _markers(self, stamp: Time, x: np.ndarray, y: np.ndarray, stations: np.ndarray,
                 y_desired: np.ndarray | None, ends_x: np.ndarray, ends_y: np.ndarray
                 ) -> MarkerArray:
        def marker(marker_id: int, kind: int, points_x, points_y, scale: float,
                   rgb: tuple[float, float, float]) -> Marker:
            m = Marker(ns='body_wave', id=marker_id, type=kind, action=Marker.ADD)
            m.header.stamp, m.header.frame_id = stamp, FRAME
            m.pose.orientation.w = 1.0
            m.scale.x = m.scale.y = m.scale.z = scale
            m.color.r, m.color.g, m.color.b = rgb
            m.color.a = 1.0
            m.points = [Point(x=float(px), y=float(py)) for px, py in zip(points_x, points_y)]
            return m

        markers = [marker(0, Marker.LINE_STRIP, x, y, 0.004, (0.1, 0.3, 0.9)),
                   marker(2, Marker.SPHERE_LIST, ends_x[:1], ends_y[:1], 0.012, (0.9, 0.5, 0.1)),
                   marker(3, Marker.CUBE_LIST, ends_x[1:], ends_y[1:], 0.012, (0.8, 0.1, 0.1))]
        if y_desired is None:
            gone = Marker(ns='body_wave', id=1, action=Marker.DELETE)
            gone.header.stamp, gone.header.frame_id = stamp, FRAME
            markers.append(gone)
        else:
            markers.append(marker(1, Marker.POINTS, stations, y_desired, 0.004,
                                  (0.2, 0.7, 0.2)))
        return MarkerArray(markers=markers)


def main(args: list[str] | None = None) -> None:
    """Run the kinematics node until shutdown."""
    run_node(KinematicsNode, args)
