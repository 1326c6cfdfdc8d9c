"""
kinematics_node: the tail's body wave and swimming-speed estimate from the servo angles.

Subscribes
    ``servo_cmd`` (sensor_msgs/JointState, sensor-data QoS; joints ``servo_1``, ``servo_2`` in
    any order, position rad, velocity rad/s optional: ``wirefish_common.servo_joints``), or the
    measured ``servo_state`` when ``use_servo_state`` is true. Samples that rule refuses are
    dropped with a warning throttled per kind. Times are the header stamps (node clock if
    unstamped).
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
    (stamped at the end of the period), eqs 16-22; all zeros while the tail is at rest
    (``tail_beat_tracker`` decides when).
Parameters: ``node_parameters``.
"""

from __future__ import annotations

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
from wirefish_common.servo_joints import JointProblem, servo_sample
from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.desired_wave import desired_wave_at_phase
from wirefish_kinematics.geometry import GEOMETRY_FIELDS
from wirefish_kinematics.lighthill import SpeedEstimate
from wirefish_kinematics.node_parameters import (declare, geometry_from, NODE_PARAMETERS,
                                                 SPECS, validate_update, wave_from,
                                                 WAVE_PARAMETER_NAMES)
from wirefish_kinematics.tail_beat_tracker import TailBeatTracker
from wirefish_kinematics.wave_spec import wave_from_message
from wirefish_kinematics.wire_coupling import bend_angles
from wirefish_msgs.msg import BodyWave, BodyWaveSpec, SpeedEstimate as SpeedEstimateMsg

FRAME = 'tail_base'
MARKERS = reliable(depth=5)
WARN_PERIOD_S = 2.0


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
        self._target = wave_from(self._values)
        self._tracker = TailBeatTracker(self._values['max_tail_beat_period_s'])
        self._latest: tuple[int, int, tuple[float, float]] | None = None
        self._fresh = False
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
            self._tracker.forget_beat()  # the overlay's phase is re-measured with it
        if names & set(WAVE_PARAMETER_NAMES):
            self._target = wave_from(self._values)
        if 'publish_rate_hz' in names:
            self.destroy_timer(self._timer)
            self._timer = self.create_timer(1.0 / self._values['publish_rate_hz'],
                                            self._on_tick)
        if 'max_tail_beat_period_s' in names:
            self._tracker.max_period_s = self._values['max_tail_beat_period_s']
        if 'use_servo_state' in names:
            self._subscribe_servo()

    def _subscribe_servo(self) -> None:
        if self._servo_sub is not None:
            self.destroy_subscription(self._servo_sub)
        topic = 'servo_state' if self._values['use_servo_state'] else 'servo_cmd'
        self._tracker.reset()
        self._latest, self._fresh = None, False
        self._servo_sub = self.create_subscription(JointState, topic, self._on_servo,
                                                   SENSOR_DATA)

    # --- inputs ---------------------------------------------------------------------------
    def _on_servo(self, msg: JointState) -> None:
        sample = servo_sample(msg)
        if isinstance(sample, JointProblem):
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
        if self._tracker.history.add(sec, nanosec, angles, rates):
            self._latest, self._fresh = (sec, nanosec, angles), True

    def _on_target(self, msg: BodyWaveSpec) -> None:
        try:
            self._target = wave_from_message(msg)
        except ValueError as error:
            self.get_logger().warn(f'target_wave ignored: {error}')

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
        report = self._tracker.update(g)
        if report is not None:
            self._publish_speed(report.estimate, report.time_s)
        y_desired = self._desired_wave(self._tracker.history.last_time(), stations)
        msg = BodyWave(q=stations.tolist(), x=x.tolist(), y=y.tolist(),
                       y_desired=[] if y_desired is None else y_desired.tolist(),
                       beta1=beta1, beta2=beta2, theta1=float(theta1), theta2=float(theta2))
        msg.header.stamp, msg.header.frame_id = stamp, FRAME
        self._body_pub.publish(msg)
        ends_x, ends_y = body_positions(np.array(g.link_end_stations), beta1, beta2, g)
        self._marker_pub.publish(self._markers(stamp, x, y, stations, y_desired,
                                               ends_x, ends_y))

    def _desired_wave(self, t: float, stations: np.ndarray) -> np.ndarray | None:
        """Return y_body at the stations, shown at the tail's phase at t; None if unknown."""
        phase = self._tracker.phase_at(t)
        if phase is None:
            return None
        w = self._target
        return desired_wave_at_phase(stations, phase, self._geometry.l1, w.c1, w.c2, w.k,
                                     w.frequency_hz)

    def _publish_speed(self, estimate: SpeedEstimate, t: float) -> None:
        msg = SpeedEstimateMsg(speed=estimate.speed, thrust=estimate.thrust,
                               drag=estimate.drag, swimming_number=estimate.swimming_number,
                               tail_beat_hz=estimate.tail_beat_hz,
                               tail_tip_amplitude=float(estimate.tail_tip_amplitude))
        msg.header.stamp = to_stamp(*self._tracker.history.stamp_of(t))
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
