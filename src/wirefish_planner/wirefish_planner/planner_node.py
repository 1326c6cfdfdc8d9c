"""
planner_node: drive the fish with cmd_vel (forward speed and yaw rate).

Subscribes
    ``cmd_vel`` (geometry_msgs/Twist, reliable): linear.x forward speed (m/s, >= 0; negative is
    refused with a throttled warning), angular.z yaw rate (rad/s, REP-103: + turns left);
    the other fields are ignored (said once per field).
    ``imu/data`` (sensor_msgs/Imu, sensor-data QoS): angular_velocity.z and the orientation's
    yaw close the yaw loops, with dt from the message stamps.
Publishes
    ``planner_state`` (wirefish_msgs/PlannerState, reliable, depth 10) at ``control_rate_hz``;
    ``/diagnostics`` (diagnostic_msgs/DiagnosticArray) at 1 Hz.
Drives
    cpg_node (``cpg_node_name``) through its ``set_parameters_atomically`` service, as
    tuner_node applies a fit: the gait (eq 18 inverted, ``gait_family``) and the offsets
    b_1 = b_2 (``yaw_control``). Every change goes through the CPG's smooth convergence, never a
    servo step. At rest (no cmd_vel yet, or none for ``cmd_vel_timeout_s``) the amplitudes and
    offsets are 0 (``rest_at_start`` false: cpg_node is left alone until the first cmd_vel).
    One request is in flight at a time; newer wishes replace older unsent ones.
Parameters: ``PLANNER_PARAMETERS`` (each with a range; an invalid set changes nothing).
"""

from __future__ import annotations

import math

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import SetParametersResult
from rcl_interfaces.srv import SetParametersAtomically
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Imu
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import declare, validate_update
from wirefish_common.qos import RELIABLE, SENSOR_DATA
from wirefish_msgs.msg import PlannerState
from wirefish_planner.planner_config import (cpg_values, planner_from, PLANNER_PARAMETERS,
                                             values_changed)
from wirefish_planner.planner_core import ignored_fields, PlannerOutput
from wirefish_planner.yaw_control import yaw_from_quaternion

SPECS = {spec.name: spec for spec in PLANNER_PARAMETERS}
DIAGNOSTICS_PERIOD_S = 1.0
WARN_THROTTLE_S = 2.0


class PlannerNode(Node):
    """cmd_vel and imu/data in; cpg_node's parameters, planner_state and /diagnostics out."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, build the planner, wire topics, client and timers."""
        super().__init__('planner_node', **kwargs)
        declare(self, PLANNER_PARAMETERS, planner_from)
        self._values = {s.name: self.get_parameter(s.name).value for s in PLANNER_PARAMETERS}
        self._planner = planner_from(self._values)
        self._said_ignored: set[str] = set()
        self._last_cmd_s: float | None = None
        self._sent: dict[str, float] | None = None  # what cpg_node last accepted
        self._in_flight: dict[str, float] | None = None
        self._refusal = ''
        self._output: PlannerOutput | None = None
        self._client = self.create_client(
            SetParametersAtomically,
            f'{self._values["cpg_node_name"]}/set_parameters_atomically')
        self.create_subscription(Twist, 'cmd_vel', self._on_cmd_vel, RELIABLE)
        self.create_subscription(Imu, 'imu/data', self._on_imu, SENSOR_DATA)
        self._state_pub = self.create_publisher(PlannerState, 'planner_state', RELIABLE)
        self._diag_pub = self.create_publisher(DiagnosticArray, '/diagnostics', RELIABLE)
        self.add_on_set_parameters_callback(self._validate)
        self.add_post_set_parameters_callback(self._apply)
        self._control_timer = self.create_timer(1.0 / self._values['control_rate_hz'],
                                                self._on_control)
        self.create_timer(DIAGNOSTICS_PERIOD_S, self._on_diagnostics)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    # --- parameters -----------------------------------------------------------------------
    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        return validate_update(SPECS, self._values, parameters, planner_from)

    def _apply(self, parameters: list[Parameter]) -> None:
        names = {p.name for p in parameters if p.name in SPECS}
        for name in names:
            self._values[name] = self.get_parameter(name).value
        if names - {'control_rate_hz', 'cpg_node_name'}:
            self._planner.reconfigure(planner_from(self._values))
        if 'control_rate_hz' in names:
            self._control_timer.cancel()
            self._control_timer = self.create_timer(1.0 / self._values['control_rate_hz'],
                                                    self._on_control)
        if 'cpg_node_name' in names:
            self.destroy_client(self._client)
            self._client = self.create_client(
                SetParametersAtomically,
                f'{self._values["cpg_node_name"]}/set_parameters_atomically')
            self._sent = None  # a new CPG node gets the whole state

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

    def _on_imu(self, msg: Imu) -> None:
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        q = msg.orientation
        yaw = yaw_from_quaternion(q.x, q.y, q.z, q.w)
        if msg.orientation_covariance[0] == -1.0:  # REP-145: no orientation
            yaw = math.nan
        self._planner.imu(self._now_s(), stamp, yaw, msg.angular_velocity.z)

    # --- outputs --------------------------------------------------------------------------
    def _on_control(self) -> None:
        now = self._now_s()
        out = self._planner.step(now)
        self._output = out
        self._send(cpg_values(out))
        self._state_pub.publish(self._state_message(out, now))

    def _send(self, wanted: dict[str, float]) -> None:
        if self._in_flight is not None or not values_changed(self._sent, wanted):
            return
        if self._last_cmd_s is None and not self._values['rest_at_start']:
            return  # cpg_node keeps its own parameters until the first cmd_vel
        if not self._client.service_is_ready():
            return
        self._in_flight = wanted
        request = SetParametersAtomically.Request(parameters=[
            Parameter(name, Parameter.Type.DOUBLE, float(value)).to_parameter_msg()
            for name, value in wanted.items()])
        self._client.call_async(request).add_done_callback(self._on_sent)

    def _on_sent(self, future) -> None:
        wanted, self._in_flight = self._in_flight, None
        try:
            result = future.result().result
        except Exception as error:  # noqa: B902 (a lost service: say why, try again later)
            self._refusal = f'set_parameters_atomically failed: {error!r}'
            self.get_logger().warn(self._refusal, throttle_duration_sec=WARN_THROTTLE_S)
            return
        if result.successful:
            self._sent, self._refusal = wanted, ''
        else:
            self._refusal = f'{self._values["cpg_node_name"]} refused: {result.reason}'
            self._sent = wanted  # not retried until the wish changes
            self.get_logger().warn(self._refusal, throttle_duration_sec=WARN_THROTTLE_S)

    def _state_message(self, out: PlannerOutput, now: float) -> PlannerState:
        point = out.gait.point
        msg = PlannerState()
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.mode = out.mode
        msg.target_speed = float(out.gait.target_speed)
        msg.predicted_speed = float(out.gait.predicted_speed)
        msg.clamp_reason = out.gait.clamp_reason
        msg.note = out.note or self._planner.gaits.family_note
        msg.gait_family = self._planner.gaits.family.name
        if point is not None:
            msg.tail_beat_hz = float(point.frequency_hz)
            msg.amplitude_scale = float(point.amplitude_scale)
            msg.cpg_frequency_hz = float(point.params.frequency_hz)
            msg.cpg_amplitude = [float(a) for a in point.params.amplitude]
        msg.yaw_rate_target = float(out.yaw_rate_target)
        msg.yaw_rate_measured = float(out.yaw_rate_measured)
        msg.yaw_rate_error = float(out.yaw_rate_target - out.yaw_rate_measured)
        msg.offset = float(out.offset)
        msg.heading_target = float(out.heading_target)
        msg.heading_measured = float(out.heading_measured)
        msg.cmd_vel_age_s = math.nan if self._last_cmd_s is None else now - self._last_cmd_s
        return msg

    def _on_diagnostics(self) -> None:
        out = self._output
        level, message = DiagnosticStatus.OK, 'ok'
        if not self._client.service_is_ready():
            level, message = DiagnosticStatus.WARN, f'no {self._client.srv_name} service'
        elif self._refusal:
            level, message = DiagnosticStatus.WARN, self._refusal
        elif out is not None and out.gait.clamp_reason:
            level, message = DiagnosticStatus.WARN, f'speed clamped: {out.gait.clamp_reason}'
        elif out is not None and out.mode == 'open_loop' and self._values['yaw_control']:
            level, message = DiagnosticStatus.WARN, 'no imu/data: turning open loop'
        elif self._planner.gaits.family_note:
            level, message = DiagnosticStatus.WARN, self._planner.gaits.family_note
        values = {} if out is None else {
            'mode': out.mode, 'target_speed': f'{out.gait.target_speed:.3f}',
            'predicted_speed': f'{out.gait.predicted_speed:.3f}',
            'yaw_rate_target': f'{out.yaw_rate_target:.3f}',
            'yaw_rate_measured': f'{out.yaw_rate_measured:.3f}',
            'offset': f'{out.offset:.4f}'}
        status = DiagnosticStatus(level=level, name=f'{self.get_fully_qualified_name()}',
                                  hardware_id='wirefish', message=message,
                                  values=[KeyValue(key=k, value=v) for k, v in values.items()])
        array = DiagnosticArray(status=[status])
        array.header.stamp = self.get_clock().now().to_msg()
        self._diag_pub.publish(array)


def main(args: list[str] | None = None) -> None:
    """Run the planner node until shutdown."""
    run_node(PlannerNode, args)
