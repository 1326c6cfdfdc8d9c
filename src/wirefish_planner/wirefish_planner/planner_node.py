# SPDX-License-Identifier: Apache-2.0
"""
planner_node: drive the fish with cmd_vel (forward speed and yaw rate).

Subscribes
    ``cmd_vel`` (geometry_msgs/Twist, reliable): linear.x forward speed (m/s, >= 0; negative is
    refused with a throttled warning), angular.z yaw rate (rad/s, REP-103: + turns left);
    the other fields are ignored (said once per field).
    ``imu/data`` (sensor_msgs/Imu, sensor-data QoS): angular_velocity.z and the orientation's
    yaw close the yaw loops, with dt from the message stamps. The samples wait in a batch
    intake's queue (``wirefish_common.batch_intake``) and each control tick reads all of them,
    oldest first, from their bytes (``cdr_views``) before it steps: the loops see every sample,
    the node is not woken 100 times a second for them.
Publishes
    ``planner_state`` (wirefish_msgs/PlannerState, reliable, depth 10) at ``control_rate_hz``;
    ``/diagnostics`` (diagnostic_msgs/DiagnosticArray) at 1 Hz.
    On simulated time (``use_sim_time``), after every control tick, ``lockstep/next_tick``
    (std_msgs/Header, reliable; ``wirefish_common.clock_hold``): when the next tick is due.
    The virtual fish's clock waits there for the tick's answer, so a fast clock never makes
    the loops skip a period (``wirefish_sim.lockstep``). A tick whose imu/data lags the clock
    (its newest sample more than ``INPUT_FRESH_S`` older than the tick) waits for the sample
    first, polling on the wall clock for at most ``INPUT_WAIT_S``: the clock is held meanwhile,
    so at ``--speed max`` a starved bridge slows the graph down instead of leaving the loops
    without their input. After a wait that ran out it waits again only once a sample has come.
    A tick that owes the CPG its start (commanded, the start not yet answered: its service not
    yet discovered, or the call in flight) answers only once the start is answered, polling on
    the wall clock for at most ``START_WAIT_S``: the fish starts at the command's time of the
    graph's clock at any ``--speed``, not when discovery and the call's round trip (wall time)
    let it. After a wait that ran out the ticks go on until that start is answered.
Drives
    cpg_node (``cpg_node_name``) by its control topic: ``cpg_command`` (wirefish_msgs/CpgCommand,
    reliable, keep last 1) in the CPG node's namespace, the whole target set at every control
    tick (no request in flight: a lost message is superseded by the next, a restarted CPG gets
    the next one): the gait (eq 18 inverted, ``gait_choice``) and the offsets b_1 = b_2
    (``yaw_control``). Every change goes through the CPG's smooth convergence, never a servo
    step. At rest (no cmd_vel yet, or none for ``cmd_vel_timeout_s``) the amplitudes and offsets
    are 0, the frequency and couplings those the CPG runs (``rest_at_start`` false: nothing is
    sent until the first cmd_vel).
Starts
    the CPG (its ``start`` service, std_srvs/Trigger) once, at the first command since start-up:
    the first cmd_vel that asks to move, or the first manual override it hears (a retune
    applied); and again a CPG restarted after that (its start service gone, then back, or a
    cpg_status that says what the last one said, or a first cpg_status after a start was
    answered: cpg_node publishes it only when it changes, and once at its start, while a CPG
    killed outright leaves its old service matched for DDS's lease time). A start is called
    again every ``START_RETRY_S`` until the CPG answers.
    Until then planner_state says ``still`` (the graph's cpg_node starts with ``autostart``
    false: the servos at neutral), or ``own_gait`` with ``rest_at_start`` false.
    Hears ``cpg_params`` (what the CPG runs: planner_state's cpg_* fields) and ``cpg_status``.
    One owner of the gait: while the CPG is under a manual override (its parameters were set,
    e.g. a retune applied) the planner sends nothing and says so (mode ``manual``); a refused
    command is said in planner_state's note and on /diagnostics.
Parameters: ``planner_node_parameters`` (each with a range; an invalid set changes nothing).
"""

from __future__ import annotations

import math
import time

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist
from rclpy.clock import Clock as RclClock, ClockType
from rclpy.node import Node
from rclpy.task import Future
from rclpy.timer import Timer
from sensor_msgs.msg import Imu
from std_srvs.srv import Trigger
from wirefish_common.batch_intake import BatchIntake, intake_qos
from wirefish_common.cdr_views import CdrError, read_imu
from wirefish_common.clock_hold import ClockHold
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import COMMAND, LATCHED, RELIABLE
from wirefish_cpg.cpg_control import TargetSource
from wirefish_cpg.cpg_messages import flat_message_values
from wirefish_msgs.msg import CpgCommand, CpgParams, CpgStatus, PlannerState
from wirefish_planner.planner_config import (command_targets, cpg_topic, cpg_values,
                                             planner_from, values_changed)
from wirefish_planner.planner_core import ignored_fields, PlannerMode, PlannerOutput
from wirefish_planner.planner_node_parameters import TABLE
from wirefish_planner.yaw_control import yaw_from_quaternion

DIAGNOSTICS_PERIOD_S = 1.0
WARN_THROTTLE_S = 2.0
# The fastest imu/data the intake's queue is sized for (twice the board's 100 Hz telemetry):
# two control ticks' samples at that rate.
MAX_IMU_RATE_HZ = 200.0
# A start call that got no answer in this long (wall s) is made again: a request to a server
# that has just appeared, or its reply, can be lost (start is idempotent). Wall time: a tick
# that waits for the answer holds the graph's clock.
START_RETRY_S = 1.0
# How long (wall s) a tick on simulated time waits for the CPG's start it owes, polling every
# START_POLL_S: discovery of a graph just started takes seconds on a loaded machine; below the
# clock's grace for a silent holder (wirefish_sim.lockstep.DEFAULT_GRACE_S).
START_WAIT_S = 3.0
START_POLL_S = 0.01
# On simulated time, how old (s of the graph's clock) the newest imu/data sample may be at a
# control tick: the bridge stamps a sample with the last step of the clock it heard, and one
# sample of the 100 Hz stream may be lost (best effort).
INPUT_FRESH_S = 0.025
# How long (wall s) a tick waits for a lagging sample, polling every INPUT_POLL_S: far below
# the clock's grace for a silent holder (wirefish_sim.lockstep.DEFAULT_GRACE_S).
INPUT_WAIT_S = 1.0
INPUT_POLL_S = 0.002


class PlannerNode(Node):
    """cmd_vel and imu/data in; cpg_command, planner_state and /diagnostics out."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, build the planner, wire topics and timers."""
        super().__init__('planner_node', **kwargs)
        self._hold = ClockHold(self)
        self._node_parameters = NodeParameters(self, TABLE, self._apply)
        self._values = self._node_parameters.values  # live: a set is in it before _apply
        self._planner = planner_from(self._values)
        self._said_ignored: set[str] = set()
        self._last_cmd_s: float | None = None
        self._sent: dict[str, float] | None = None  # the targets cpg_command carries
        self._cpg_params: CpgParams | None = None  # what the CPG last said it runs
        self._cpg_status: CpgStatus | None = None
        self._output: PlannerOutput | None = None
        # No command since start-up: the tail is still (or swims the CPG's own start-up gait).
        self._commanded = False
        self._start_pending = False  # the CPG's start is due, its service not yet seen
        self._cpg_started = False  # a start call was answered (by this cpg_node or one before)
        self._cpg_was_ready: bool | None = None  # the CPG's start service at the last tick
        self._start_call: tuple[float, Future] | None = None  # (wall s, answer) in flight
        self._start_wait: tuple[float, Timer] | None = None  # (wall start, poll) of a tick
        self._start_wait_ran_out = False  # ticks go on without the owed start until answered
        self._wire_cpg()
        self.create_subscription(Twist, 'cmd_vel', self._on_cmd_vel, RELIABLE)
        self._imu_intake: BatchIntake | None = None
        self._subscribe_imu()
        self._state_pub = self.create_publisher(PlannerState, 'planner_state', RELIABLE)
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', RELIABLE)
        self._control_timer = self.create_timer(1.0 / self._values['control_rate_hz'],
                                                self._on_control)
        self._newest_imu_s: float | None = None  # the newest imu/data stamp taken
        self._input_came = True  # a sample came since the last wait that ran out
        self._waiting: tuple[float, float] | None = None  # (tick, wall start) of a waiting tick
        self._wait_timer: Timer | None = None
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._on_diagnostics)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # --- parameters -----------------------------------------------------------------------
    def _apply(self, names: frozenset[str]) -> None:
        if names - {'control_rate_hz', 'cpg_node_name'}:
            self._planner.reconfigure(planner_from(self._values))
        if 'control_rate_hz' in names:
            self._control_timer.cancel()
            self._control_timer = self.create_timer(1.0 / self._values['control_rate_hz'],
                                                    self._on_control)
            # The clock may be held at the cancelled timer's tick.
            self._hold.say_next_tick(self._control_timer)
            self._subscribe_imu()  # its queue holds the samples of two ticks
        if 'cpg_node_name' in names:
            self.destroy_publisher(self._command_pub)
            for subscription in self._cpg_subscriptions:
                self.destroy_subscription(subscription)
            self.destroy_client(self._start_client)
            self._sent = self._cpg_params = self._cpg_status = None
            self._start_call = None
            self._cpg_started = False
            self._wire_cpg()

    def _wire_cpg(self) -> None:
        """Create cpg_command's publisher and the cpg_params, cpg_status subscriptions."""
        name = self._values['cpg_node_name']
        self._command_pub = self.create_publisher(CpgCommand, cpg_topic(name, 'cpg_command'),
                                                  COMMAND)
        self._cpg_subscriptions = [
            self.create_subscription(CpgParams, cpg_topic(name, 'cpg_params'),
                                     self._on_cpg_params, LATCHED),
            self.create_subscription(CpgStatus, cpg_topic(name, 'cpg_status'),
                                     self._on_cpg_status, LATCHED)]
        self._start_client = self.create_client(Trigger, cpg_topic(name, 'start'))

    def _on_cpg_params(self, msg: CpgParams) -> None:
        self._cpg_params = msg

    def _on_cpg_status(self, msg: CpgStatus) -> None:
        previous, self._cpg_status = self._cpg_status, msg
        # cpg_node says its status once at its start and then only when it changes: the same
        # status again is a new cpg_node, and so is a first status heard after a start was
        # answered (the one started may have died before its own status reached this node).
        # A new one starts still; a start of one that runs answers 'already running'.
        if self._commanded and (
                (previous is None and self._cpg_started) or (
                    previous is not None
                    and (previous.source, previous.refused) == (msg.source, msg.refused))):
            self._start_pending = True
            self._start_cpg()
        if self._manual():  # a retune applied is a command: the fish swims the fit
            self._first_command()

    def _first_command(self) -> None:
        """Start the CPG at the first command since start-up (it starts with the tail still)."""
        if not self._commanded:
            self._commanded = True
            self._start_pending = True
            self._start_cpg()

    def _start_cpg(self) -> None:
        """
        Call the CPG's start once its service is there (the next tick retries until then).

        A CPG that comes back after it was gone (restarted, its start service seen again)
        starts still like any: once commanded, the planner starts it again.
        """
        ready = self._start_client.service_is_ready()
        if self._commanded and self._cpg_was_ready is False and ready:
            self._start_pending = True
        self._cpg_was_ready = ready
        if self._start_call is not None:
            sent_s, answer = self._start_call
            if answer.done():
                self._start_call = None
                self._start_pending = False
                self._start_wait_ran_out = False
                self._cpg_started = True
            elif time.monotonic() - sent_s >= START_RETRY_S:
                self._start_client.remove_pending_request(answer)  # no answer: call again
                self._start_call = None
            else:
                return
        if self._start_pending and ready:
            self._start_call = (time.monotonic(),
                                self._start_client.call_async(Trigger.Request()))

    # --- inputs ---------------------------------------------------------------------------
    def _on_cmd_vel(self, msg: Twist) -> None:
        now = self._now_s()
        linear = (msg.linear.x, msg.linear.y, msg.linear.z)
        angular = (msg.angular.x, msg.angular.y, msg.angular.z)
        for name in ignored_fields(linear, angular):
            if name not in self._said_ignored:
                self._said_ignored.add(name)
                self.get_logger().info(f'cmd_vel {name} is ignored (a fish swims forward and '
                                       'turns about z only); said once')
        problem = self._planner.command(now, msg.linear.x, msg.angular.z)
        if problem is not None:
            self.get_logger().warn(problem, throttle_duration_sec=WARN_THROTTLE_S)
            return
        self._last_cmd_s = now
        if msg.linear.x > 0.0 or msg.angular.z != 0.0:
            self._first_command()

    def _subscribe_imu(self) -> None:
        if self._imu_intake is not None:
            self._imu_intake.destroy()
        self._imu_intake = BatchIntake(self, Imu, 'imu/data',
                                       intake_qos(MAX_IMU_RATE_HZ,
                                                  self._values['control_rate_hz']))

    def _take_imu(self, now: float) -> None:
        """Feed the yaw loops every imu/data sample since the last tick, oldest first."""
        assert self._imu_intake is not None
        for data in self._imu_intake.take():
            try:
                view = read_imu(data)
            except CdrError as error:  # DDS delivered it whole: a foreign writer's bytes
                self.get_logger().warn(f'imu/data sample not read: {error}',
                                       throttle_duration_sec=WARN_THROTTLE_S)
                continue
            stamp = view.sec + view.nanosec * 1e-9
            if self._newest_imu_s is None or stamp > self._newest_imu_s:
                self._newest_imu_s = stamp
                self._input_came = True
            # REP-145: a covariance of -1 says there is no orientation (yaw NaN: not used)
            yaw = yaw_from_quaternion(*view.orientation) \
                if view.orientation_covariance_0 != -1.0 else math.nan
            self._planner.imu(now, stamp, yaw, view.angular_velocity[2])

    def destroy_node(self) -> None:
        """Destroy the imu intake's reader node too."""
        if self._imu_intake is not None:
            self._imu_intake.destroy()
            self._imu_intake = None
        super().destroy_node()

    # --- outputs --------------------------------------------------------------------------
    def _on_control(self) -> None:
        if self._waiting is not None:  # the clock went on without the tick (released)
            self._end_wait()
        if self._start_wait is not None:
            self._end_start_wait()
        now = self._now_s()
        self._take_imu(now)
        if self._input_lags(now):
            self._waiting = (now, time.monotonic())
            self._wait_timer = self.create_timer(INPUT_POLL_S, self._poll_input,
                                                 clock=RclClock(clock_type=ClockType.STEADY_TIME))
            return
        self._control(now)

    def _input_lags(self, tick: float) -> bool:
        """Return whether a tick on simulated time should wait for imu/data (see module)."""
        return (self._hold.on_simulated_time and self._input_came
                and self._newest_imu_s is not None
                and tick - self._newest_imu_s > INPUT_FRESH_S)

    def _poll_input(self) -> None:
        assert self._waiting is not None
        tick, since = self._waiting
        self._take_imu(tick)
        if not self._input_lags(tick):
            self._end_wait()
        elif time.monotonic() - since > INPUT_WAIT_S:
            self._input_came = False
            self.get_logger().warn(
                f'imu/data lags the clock: no sample newer than {self._newest_imu_s:.3f} s at '
                f'the tick of {tick:.3f} s after {INPUT_WAIT_S:g} s of waiting; the ticks go on '
                'without it until one comes', throttle_duration_sec=WARN_THROTTLE_S)
            self._end_wait()

    def _end_wait(self) -> None:
        """Run the waiting tick with what came."""
        assert self._waiting is not None
        tick = self._waiting[0]
        self._waiting = None
        if self._wait_timer is not None:
            self.destroy_timer(self._wait_timer)
            self._wait_timer = None
        self._control(tick)

    def _control(self, now: float) -> None:
        """Run the control tick of simulated or wall time ``now`` (s)."""
        out = self._planner.step(now)
        self._output = out
        self._start_cpg()
        if self._manual():
            self._planner.pi.reset()  # the planner's offset is not applied: nothing to integrate
        else:
            self._send(cpg_values(out))
        self._state_pub.publish(self._state_message(out, now))
        if self._owes_start():
            self._start_wait = (time.monotonic(), self.create_timer(
                START_POLL_S, self._poll_start, clock=RclClock(clock_type=ClockType.STEADY_TIME)))
            return
        self._hold.say_next_tick(self._control_timer)

    def _owes_start(self) -> bool:
        """Return whether a tick on simulated time should wait for the CPG's start (module)."""
        return (self._hold.on_simulated_time and self._start_pending
                and not self._start_wait_ran_out)

    def _poll_start(self) -> None:
        assert self._start_wait is not None
        self._start_cpg()
        if not self._owes_start():
            self._end_start_wait()
        elif time.monotonic() - self._start_wait[0] > START_WAIT_S:
            self._start_wait_ran_out = True
            ready = self._start_client.service_is_ready()
            self.get_logger().warn(
                f'the CPG did not answer its start within {START_WAIT_S:g} s '
                f'({"called" if ready else "its start service not seen"}); the ticks go on '
                'and the start is called again until it answers',
                throttle_duration_sec=WARN_THROTTLE_S)
            self._end_start_wait()

    def _end_start_wait(self) -> None:
        """Answer the tick that waited for the CPG's start."""
        assert self._start_wait is not None
        self.destroy_timer(self._start_wait[1])
        self._start_wait = None
        self._hold.say_next_tick(self._control_timer)

    def _manual(self) -> bool:
        status = self._cpg_status
        return status is not None and status.source == TargetSource.MANUAL.value

    def _refusal(self) -> str:
        """Return why the CPG does not run the planner's targets ('' when it does)."""
        status = self._cpg_status
        if status is None:
            return ''
        if self._manual():
            name = self._values['cpg_node_name']
            return (f'{name} is under a manual override (its parameters were set, e.g. a retune '
                    f'applied): cmd_vel is not followed until {name}/follow_commands is called')
        return status.refused

    def _send(self, wanted: dict[str, float]) -> None:
        """Publish the targets (the last ones again if ``wanted`` is within the deadband)."""
        if self._last_cmd_s is None and not self._values['rest_at_start']:
            return  # cpg_node keeps its own parameters until the first cmd_vel
        running = None if self._cpg_params is None else flat_message_values(self._cpg_params)
        targets = command_targets(wanted, running)
        if targets is None:
            return  # at rest before the CPG said what it runs: nothing to rest from yet
        if self._sent is None or values_changed(self._sent, targets):
            self._sent = targets
        sent = self._sent
        msg = CpgCommand()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.targets = CpgParams(
            frequency_hz=sent['frequency_hz'],
            amplitude=[sent['amplitude_1'], sent['amplitude_2']],
            offset=[sent['offset_1'], sent['offset_2']], w12=sent['w12'], w21=sent['w21'],
            phi12=sent['phi12'], phi21=sent['phi21'], alpha=sent['alpha'])
        self._command_pub.publish(msg)

    def _state_message(self, out: PlannerOutput, now: float) -> PlannerState:
        point = out.gait.point
        msg = PlannerState()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.mode = str(self._mode(out))
        msg.target_speed = float(out.gait.target_speed)
        msg.predicted_speed = float(out.gait.predicted_speed)
        msg.clamp_reason = out.gait.clamp_reason
        msg.note = self._refusal() or out.note or self._planner.gaits.family_note
        msg.gait_family = self._planner.gaits.family.name
        if point is not None:
            msg.tail_beat_hz = float(point.frequency_hz)
            msg.amplitude_scale = float(point.amplitude_scale)
        running = self._cpg_params  # what the CPG runs, as it says (not what was asked)
        msg.cpg_frequency_hz = math.nan if running is None else float(running.frequency_hz)
        msg.cpg_amplitude = [math.nan] * 2 if running is None else [
            float(a) for a in running.amplitude]
        msg.yaw_rate_target = float(out.yaw_rate_target)
        msg.yaw_rate_measured = float(out.yaw_rate_measured)
        msg.yaw_rate_error = float(out.yaw_rate_target - out.yaw_rate_measured)
        msg.offset = float(out.offset)
        msg.heading_target = float(out.heading_target)
        msg.heading_measured = float(out.heading_measured)
        msg.cmd_vel_age_s = math.nan if self._last_cmd_s is None else now - self._last_cmd_s
        return msg

    def _mode(self, out: PlannerOutput) -> PlannerMode:
        """Return what the tail does: the planner's mode, or why the planner does not drive it."""
        if self._manual():
            return PlannerMode.MANUAL
        if not self._commanded:
            return PlannerMode.STILL if self._values['rest_at_start'] else PlannerMode.OWN_GAIT
        return out.mode

    def _on_diagnostics(self) -> None:
        out = self._output
        level, message = DiagnosticStatus.OK, 'ok'
        if self._refusal():
            level, message = DiagnosticStatus.WARN, self._refusal()
        elif self._command_pub.get_subscription_count() == 0:
            level, message = DiagnosticStatus.WARN, f'nobody hears {self._command_pub.topic_name}'
        elif out is not None and out.gait.clamp_reason:
            level, message = DiagnosticStatus.WARN, f'speed clamped: {out.gait.clamp_reason}'
        elif (out is not None and out.mode == PlannerMode.OPEN_LOOP
              and self._values['yaw_control']):
            level, message = DiagnosticStatus.WARN, 'no imu/data: turning open loop'
        elif self._planner.gaits.family_note:
            level, message = DiagnosticStatus.WARN, self._planner.gaits.family_note
        values = {} if out is None else {
            'mode': str(self._mode(out)), 'target_speed': f'{out.gait.target_speed:.3f}',
            'predicted_speed': f'{out.gait.predicted_speed:.3f}',
            'yaw_rate_target': f'{out.yaw_rate_target:.3f}',
            'yaw_rate_measured': f'{out.yaw_rate_measured:.3f}',
            'offset': f'{out.offset:.4f}',
            'cpg_source': 'unknown' if self._cpg_status is None else self._cpg_status.source}
        status = DiagnosticStatus(level=level, name=f'{self.get_fully_qualified_name()}',
                                  hardware_id='wirefish', message=message,
                                  values=[KeyValue(key=k, value=v) for k, v in values.items()])
        array = DiagnosticArray(status=[status])
        array.header.stamp = self.get_clock().now().to_msg()
        self._diag_pub.publish(array)


def main(args: list[str] | None = None) -> None:
    """Run the planner node until shutdown."""
    run_node(PlannerNode, args)
