# SPDX-License-Identifier: Apache-2.0
"""
cpg_node: the fish's two-oscillator CPG (paper eq 1) driving the servos.

Publishes
    ``servo_cmd`` (sensor_msgs/JointState, sensor-data QoS) at ``publish_rate_hz``: joints
    ``servo_1``, ``servo_2`` (``wirefish_common.servo_joints``); position (rad) and velocity
    (rad/s), stamped with the node clock. On the wall clock the ticks come from a
    ``FixedRateLoop`` thread, not an executor timer: at 1 kHz the executor's own overhead was
    ~90 % of the node's CPU (see fixed_rate.py). With ``use_sim_time`` (fish_sim's /clock, the
    virtual fish's lockstep road) they come from a timer on the node clock instead: one tick at
    every multiple of the period that simulated time reaches, so each step of fish_sim's clock
    (one period) draws exactly the one command it waits for; a tick at which simulated time
    has not moved publishes nothing, and a clock that jumps back (a restarted fish_sim) re-bases
    the CPG's clock, keeping its state.
    ``cpg_params`` (wirefish_msgs/CpgParams, reliable, transient local, depth 1): the targets
    the CPG runs, re-published whenever they change (from a command, a parameter set, start or
    stop). While stopped that is ``oscillator.at_rest`` of the targets (amplitudes and offsets
    0), never the targets kept for start: a bridge in gait mode sends cpg_params to the board
    as its gait, so a stopped CPG must not say it swims.
    ``cpg_status`` (wirefish_msgs/CpgStatus, reliable, transient local, depth 1): which source
    sets the targets and why the last command was refused, re-published when it changes.
Subscribes
    ``cpg_command`` (wirefish_msgs/CpgCommand, reliable, keep last 1): the control signal (the
    planner's targets), judged as a parameter set is (``cpg_control``).
Services
    ``start``, ``stop`` (std_srvs/Trigger): stop sends the amplitude and offset targets to 0,
    so the tail comes to rest along eq 1's convergence law, never by a jump; start restores
    the targets. Changes while stopped are kept and apply at start.
    ``~/follow_commands`` (std_srvs/Trigger): end a manual override (``cpg_control`` says which
    source wins: a parameter set overrides cpg_command until this is called).
Parameters (flat scalars, each with a range; invalid updates are rejected with a reason):
    see ``cpg_node_parameters``; the configuration and the manual override. Valid targets apply
    smoothly: the oscillator state persists, the amplitudes and offsets converge to their new
    targets, a new frequency only changes the phase velocity. Outputs beyond
    ``servo_limit_rad`` are clamped (rate 0) with a warning.
"""

from __future__ import annotations

import threading

from rclpy.node import Node
from rclpy.timer import Timer
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import COMMAND, LATCHED, SENSOR_DATA
from wirefish_common.servo_joints import servo_joint_state
from wirefish_cpg.cpg_control import CpgTargets, TargetSource
from wirefish_cpg.cpg_messages import flat_message_values, to_message
from wirefish_cpg.cpg_node_parameters import CPG_PARAMETER_NAMES, TABLE
from wirefish_cpg.fixed_rate import FixedRateLoop
from wirefish_cpg.oscillator import at_rest, CpgIntegrator, CpgParameters
from wirefish_cpg.servo_limit import clamp_to_limit
from wirefish_msgs.msg import CpgCommand, CpgParams, CpgStatus

# Longest clock gap integrated step by step (s); a longer jump re-bases the clock instead.
MAX_CATCH_UP_S = 0.5


class CpgNode(Node):
    """Integrates eq 1 on the node clock and publishes the servo commands."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters, wire the topics and services, start the publish loop."""
        super().__init__('cpg_node', **kwargs)
        self._node_parameters = NodeParameters(self, TABLE, self._apply)
        self._values = self._node_parameters.values  # live: a set is in it before _apply
        self._control = CpgTargets(TABLE.by_name, self._values, self.get_fully_qualified_name())
        self._running = bool(self._values['autostart'])
        params = self._runs()
        # The CPG is stepped on the loop's thread and re-parameterised on the executor's.
        self._lock = threading.Lock()
        self._last_tick_ns = -1
        self._cpg = CpgIntegrator(params,
                                  step_s=self._values['integration_step_s'],
                                  time_s=self._now_s())
        self._servo_pub = self.create_publisher(JointState, 'servo_cmd',
                                                SENSOR_DATA)
        # One message, refilled at every tick (only the loop's thread touches it): building a
        # JointState with its names and stamp was a fifth of a tick's CPU.
        self._command = servo_joint_state((0.0, 0.0), (0.0, 0.0))
        self._params_pub = self.create_publisher(CpgParams, 'cpg_params', LATCHED)
        self._status_pub = self.create_publisher(CpgStatus, 'cpg_status', LATCHED)
        self._status: tuple[TargetSource, str] | None = None  # what cpg_status last said
        self.create_service(Trigger, 'start', self._on_start)
        self.create_service(Trigger, 'stop', self._on_stop)
        self.create_service(Trigger, '~/follow_commands', self._on_follow_commands)
        self.create_subscription(CpgCommand, 'cpg_command', self._on_command, COMMAND)
        self._params_pub.publish(to_message(params))
        self._publish_status()
        period_s = 1.0 / self._values['publish_rate_hz']
        self._loop: FixedRateLoop | None = None
        self._timer: Timer | None = None
        if self.get_parameter('use_sim_time').value:
            self._timer = self.create_timer(period_s, self._on_tick)
        else:
            self._loop = FixedRateLoop(period_s, self._on_tick, name='cpg_publish')
            self._loop.start()

    def destroy_node(self) -> None:
        """Stop the publish loop before the publisher goes away."""
        if self._loop is not None:
            self._loop.stop()
        super().destroy_node()

    def _runs(self) -> CpgParameters:
        """Return what the oscillator runs: the targets, or at rest while stopped."""
        targets = self._control.targets
        return targets if self._running else at_rest(targets)

    def _now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _apply(self, names: frozenset[str]) -> None:
        params = None
        with self._lock:
            if 'integration_step_s' in names:
                self._cpg.step_s = float(self._values['integration_step_s'])
            if 'publish_rate_hz' in names:
                period_s = 1.0 / self._values['publish_rate_hz']
                if self._loop is not None:
                    self._loop.period_s = period_s
                elif self._timer is not None:
                    self._timer.timer_period_ns = round(period_s * 1e9)
            if names & set(CPG_PARAMETER_NAMES):  # a manual override (cpg_control)
                self._control.parameters_set(self._values)
                params = self._runs()
                self._cpg.set_parameters(params)
        if params is not None:  # announced outside the lock: the loop must not wait on DDS
            self._params_pub.publish(to_message(params))
            self._publish_status()

    def _on_command(self, msg: CpgCommand) -> None:
        with self._lock:
            previous = self._runs()
            applied = self._control.command(self._values, flat_message_values(msg.targets))
            runs = self._runs()
            if runs != previous:
                self._cpg.set_parameters(runs)
        if runs != previous:
            self._params_pub.publish(to_message(runs))
        if not applied:
            self.get_logger().warn(self._control.refused, throttle_duration_sec=2.0)
        self._publish_status()

    def _publish_status(self) -> None:
        """Publish cpg_status if the source or the verdict changed since it was last said."""
        status = (self._control.source, self._control.refused)
        if status == self._status:
            return
        self._status = status
        msg = CpgStatus(source=status[0].value, refused=status[1])
        msg.header.stamp = self.get_clock().now().to_msg()
        self._status_pub.publish(msg)

    def _on_follow_commands(self, request: Trigger.Request, response: Trigger.Response
                            ) -> Trigger.Response:
        response.success = True
        response.message = ('cpg_command sets the targets again' if self._control.follow_commands()
                            else 'already following cpg_command')
        self._publish_status()
        return response

    def _on_start(self, request: Trigger.Request, response: Trigger.Response
                  ) -> Trigger.Response:
        response.success = True
        response.message = 'already running' if self._running else 'started'
        with self._lock:
            changed = not self._running
            self._running = True
            runs = self._runs()
            self._cpg.set_parameters(runs)
        if changed:
            self._params_pub.publish(to_message(runs))
        return response

    def _on_stop(self, request: Trigger.Request, response: Trigger.Response
                 ) -> Trigger.Response:
        response.success = True
        response.message = ('stopping: amplitudes and offsets converge to 0'
                            if self._running else 'already stopped')
        with self._lock:
            changed = self._running
            self._running = False
            runs = self._runs()
            self._cpg.set_parameters(runs)
        if changed:
            self._params_pub.publish(to_message(runs))
        return response

    def _on_tick(self) -> None:
        try:
            self._publish_command()
        except Exception as error:  # noqa: B902 (the loop's thread must survive; say why)
            if not self.context.ok():  # shut down under the loop (Ctrl-C): nothing to say
                if self._loop is not None:
                    self._loop.stop()
                return
            self.get_logger().error(f'servo_cmd tick failed: {error!r}',
                                    throttle_duration_sec=2.0)

    def _publish_command(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        if now_ns == self._last_tick_ns:  # simulated time stands still (back: re-based below)
            return
        self._last_tick_ns = now_ns
        t = now_ns * 1e-9
        with self._lock:
            self._cpg.advance(t, max_steps=int(MAX_CATCH_UP_S / self._cpg.step_s))
            angles, rates = self._cpg.output(t)
            limit = self._values['servo_limit_rad']
        commanded, rates, clamped = clamp_to_limit(angles, rates, limit)
        if clamped:
            self.get_logger().warn(
                f'CPG output [{angles[0]:.3f}, {angles[1]:.3f}] rad beyond servo_limit_rad = '
                f'{limit:g}; clamped', throttle_duration_sec=2.0)
        msg = self._command
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now_ns, 1_000_000_000)
        msg.position = commanded
        msg.velocity = rates
        self._servo_pub.publish(msg)


def main(args: list[str] | None = None) -> None:
    """Run the CPG node until shutdown."""
    run_node(CpgNode, args)
