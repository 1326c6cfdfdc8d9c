# SPDX-License-Identifier: Apache-2.0
"""
kinematics_node: the tail's body wave and swimming-speed estimate from the servo angles.

Subscribes
    ``servo_cmd`` (sensor_msgs/JointState, sensor-data QoS; joints ``servo_1``, ``servo_2`` in
    any order, position rad, velocity rad/s optional: ``wirefish_common.servo_joints``), or the
    measured ``servo_state`` when ``use_servo_state`` is true, taken in batches: the samples
    wait in the intake's queue (``wirefish_common.batch_intake``) and each tick reads all of
    them from their bytes (``cdr_views``). Samples that rule refuses are dropped with a
    warning throttled per kind. Times are the header stamps (node clock if unstamped).
    ``target_wave`` (wirefish_msgs/BodyWaveSpec, reliable, transient local): the desired wave;
    the latest of it and the ``wave_*`` parameters wins.
Publishes (frame ``tail_base`` = C0 of paper section 3.1)
    ``body_wave`` (wirefish_msgs/BodyWave, sensor data) at ``publish_rate_hz`` of the
    samples' own stamps: the samples are decimated by their stamps (``decimator``), each one
    due published from its own angles and stamp, so a late tick publishes the ones it missed
    and the rate holds in the graph's time (simulated on the virtual fish);
    ``station_count`` stations, eqs 2-15; ``y_desired`` (eq 23) once the tail beats, shown at
    the tail's phase (see ``desired_wave.wave_time_at_phase``).
    ``body_wave_markers`` (visualization_msgs/MarkerArray, reliable depth 5, so RViz's default
    subscription matches) with every n-th body_wave, n = round(publish_rate_hz /
    markers_rate_hz) (10 Hz by default: they cost more than the body wave): tail polyline,
    desired wave as dots, link ends O1 (sphere) and O2 (cube).
    ``speed_estimate`` (wirefish_msgs/SpeedEstimate, reliable) once per completed tail beat
    (stamped at the end of the period), eqs 16-22; all zeros while the tail is at rest
    (``tail_beat_tracker`` decides when).
    On simulated time (``use_sim_time``), after every tick, ``lockstep/next_tick``
    (std_msgs/Header; ``wirefish_common.clock_hold``): when the next tick is due. The virtual
    fish's clock waits there for the tick, so a fast clock never runs further ahead of the tick
    than the intake's queue holds: at --speed max beside two other graphs the queue overflowed
    and body_wave lost 1 % of its samples (49.5 Hz of 50 in simulated time).
Parameters: ``kinematics_node_parameters``.
"""

from __future__ import annotations

import math

import numpy as np
from rclpy.node import Node
from sensor_msgs.msg import JointState
from visualization_msgs.msg import MarkerArray
from wirefish_common.batch_intake import BatchIntake, intake_qos
from wirefish_common.cdr_views import CdrError, read_joint_state
from wirefish_common.clock_hold import ClockHold
from wirefish_common.decimator import Decimator
from wirefish_common.frames import declare_frame_prefix, prefixed
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import LATCHED, RELIABLE, reliable, SENSOR_DATA
from wirefish_common.servo_joints import JointProblem, servo_sample
from wirefish_kinematics.desired_wave import desired_wave_at_phase
from wirefish_kinematics.geometry import GEOMETRY_FIELDS
from wirefish_kinematics.geometry_parameters import geometry_from
from wirefish_kinematics.kinematics_messages import (body_wave_markers, body_wave_message, FRAME,
                                                     speed_estimate_message, to_stamp)
from wirefish_kinematics.kinematics_node_parameters import (markers_every, TABLE, wave_from,
                                                            WAVE_PARAMETER_NAMES)
from wirefish_kinematics.tail_beat_tracker import TailBeatTracker
from wirefish_kinematics.tail_shape import tail_shape
from wirefish_kinematics.wave_spec import wave_from_message
from wirefish_msgs.msg import BodyWave, BodyWaveSpec, SpeedEstimate as SpeedEstimateMsg

MARKERS = reliable(depth=5)
# The fastest servo_cmd the CPG publishes (its publish_rate_hz range): the intake's queue holds
# two ticks' samples at that rate.
MAX_SERVO_RATE_HZ = 1000.0
WARN_PERIOD_S = 2.0


class KinematicsNode(Node):
    """Computes the body wave and the Lighthill speed estimate from servo angles."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters; wire subscriptions, publishers and the publish timer."""
        super().__init__('kinematics_node', **kwargs)
        self._hold = ClockHold(self)
        self._node_parameters = NodeParameters(self, TABLE, self._apply)
        self._frame = prefixed(declare_frame_prefix(self), FRAME)  # fish_1/tail_base
        self._values = self._node_parameters.values  # live: a set is in it before _apply
        self._geometry = geometry_from(self._values)
        self._target = wave_from(self._values)
        self._tracker = TailBeatTracker(self._values['max_tail_beat_period_s'])
        # The last sample (sec, nanosec, angles, history time s): shown again on a new geometry.
        self._latest: tuple[int, int, tuple[float, float], float] | None = None
        self._fresh = False
        self._due = Decimator(self._values['publish_rate_hz'])
        self._markers_every = 1
        self._ticks_to_markers = 0  # body_wave ticks before the next markers (0: this one)
        self._set_markers_rate()
        self._warned: dict[str, float] = {}
        self._body_pub = self.create_publisher(BodyWave, 'body_wave', SENSOR_DATA)
        # Reliable, unlike the data streams: RViz subscribes to markers reliably by default, and
        # a best-effort publisher would never match it. A reliable one matches both kinds.
        self._marker_pub = self.create_publisher(MarkerArray, 'body_wave_markers', MARKERS)
        self._speed_pub = self.create_publisher(SpeedEstimateMsg, 'speed_estimate', RELIABLE)
        self.create_subscription(BodyWaveSpec, 'target_wave', self._on_target, LATCHED)
        self._servo_sub: BatchIntake | None = None
        self._subscribe_servo()
        self._timer = self.create_timer(1.0 / self._values['publish_rate_hz'], self._on_tick)

    # --- parameters -----------------------------------------------------------------------
    def _apply(self, names: frozenset[str]) -> None:
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
            self._hold.say_next_tick(self._timer)  # not the destroyed timer's tick
            self._subscribe_servo()  # its queue holds the samples of a tick
            self._due.rate_hz = self._values['publish_rate_hz']
        if names & {'publish_rate_hz', 'markers_rate_hz'}:
            self._set_markers_rate()
        if 'max_tail_beat_period_s' in names:
            self._tracker.max_period_s = self._values['max_tail_beat_period_s']
        if 'use_servo_state' in names:
            self._subscribe_servo()

    def _set_markers_rate(self) -> None:
        self._markers_every = markers_every(self._values['publish_rate_hz'],
                                            self._values['markers_rate_hz'])
        self._ticks_to_markers = 0

    def _subscribe_servo(self) -> None:
        # The samples wait in the intake's queue until the tick takes them all: no wake-up
        # of this node per servo sample (message_cost: 6.3 -> 3.9 % of a core at 200 Hz).
        if self._servo_sub is not None:
            self._servo_sub.destroy()
        topic = 'servo_state' if self._values['use_servo_state'] else 'servo_cmd'
        self._tracker.reset()
        self._latest, self._fresh = None, False
        self._servo_sub = BatchIntake(self, JointState, topic,
                                      intake_qos(MAX_SERVO_RATE_HZ,
                                                 self._values['publish_rate_hz']))

    def destroy_node(self) -> None:
        """Destroy the servo intake's reader node too."""
        if self._servo_sub is not None:
            self._servo_sub.destroy()
            self._servo_sub = None
        super().destroy_node()

    # --- inputs ---------------------------------------------------------------------------
    def _on_servo(self, data: bytes) -> tuple[int, int, tuple[float, float], float] | None:
        """Take one servo sample's bytes into the history; return it, or None if refused."""
        try:
            view = read_joint_state(data)
            sample = servo_sample(view)
        except CdrError as error:
            sample = JointProblem('bytes', str(error))
        if isinstance(sample, JointProblem):
            # throttled per kind, so that one bad source cannot hide another
            now = self.get_clock().now().nanoseconds * 1e-9
            if now - self._warned.get(sample.kind, -math.inf) >= WARN_PERIOD_S:
                self._warned[sample.kind] = now
                self.get_logger().warn(f'{sample.message}; sample dropped')
            return None
        sec, nanosec = view.sec, view.nanosec
        if sec == 0 and nanosec == 0:
            sec, nanosec = self.get_clock().now().seconds_nanoseconds()
        angles, rates = sample
        if not self._tracker.history.add(sec, nanosec, angles, rates):
            return None
        self._latest = (sec, nanosec, angles, self._tracker.history.last_time())
        return self._latest

    def _on_target(self, msg: BodyWaveSpec) -> None:
        try:
            self._target = wave_from_message(msg)
        except ValueError as error:
            self.get_logger().warn(f'target_wave ignored: {error}')

    # --- outputs --------------------------------------------------------------------------
    def _on_tick(self) -> None:
        self._publish_due()
        self._hold.say_next_tick(self._timer)

    def _publish_due(self) -> None:
        """Take the queued servo samples; publish those due and the speed estimate of a beat."""
        due = []
        if self._servo_sub is not None:
            for data in self._servo_sub.take():
                sample = self._on_servo(data)
                if sample is not None and self._due.due(sample[0] + 1e-9 * sample[1]):
                    due.append(sample)
        if not due and self._fresh and self._latest is not None:
            due.append(self._latest)  # the last sample again, on the new geometry
        self._fresh = False
        if not due:
            return
        report = self._tracker.update(self._geometry)
        if report is not None:
            self._speed_pub.publish(speed_estimate_message(
                report.estimate, to_stamp(*self._tracker.history.stamp_of(report.time_s)),
                self._frame))
        for sample in due:
            self._publish_body_wave(*sample)

    def _publish_body_wave(self, sec: int, nanosec: int, angles: tuple[float, float],
                           t: float) -> None:
        """Publish the body wave of one servo sample (and every n-th time, its markers)."""
        stamp = to_stamp(sec, nanosec)
        shape = tail_shape(angles, self._geometry, self._values['station_count'])
        y_desired = self._desired_wave(t, shape.stations)
        self._body_pub.publish(body_wave_message(shape, y_desired, stamp, self._frame))
        if self._ticks_to_markers == 0:
            self._marker_pub.publish(body_wave_markers(shape, y_desired, stamp, self._frame))
            self._ticks_to_markers = self._markers_every
        self._ticks_to_markers -= 1

    def _desired_wave(self, t: float, stations: np.ndarray) -> np.ndarray | None:
        """Return y_body at the stations, shown at the tail's phase at t; None if unknown."""
        phase = self._tracker.phase_at(t)
        if phase is None:
            return None
        w = self._target
        return desired_wave_at_phase(stations, phase, self._geometry.l1, w.c1, w.c2, w.k,
                                     w.frequency_hz)


def main(args: list[str] | None = None) -> None:
    """Run the kinematics node until shutdown."""
    run_node(KinematicsNode, args)
