# SPDX-License-Identifier: Apache-2.0
"""
fish_sim: virtual fish on pseudo-terminals, playing the boards' firmware in real time.

``fish_sim --link /tmp/wirefish-tty`` opens a pty pair, prints the device path on stdout (one
line, flushed), points the link at it and runs until SIGINT/SIGTERM (exit code 0). Each further
``--link`` is one more fish of the same process (a fleet: one clock, one physics vectorised over
the fish, ``VirtualFleet``), each on a pty of its own, one device line each in order. The core
needs no ROS; with ``--ros`` the process also publishes each fish's ``sim/ground_truth``
(nav_msgs/Odometry, frame ``odom``, child ``base_link``, both under the ROS parameter
``frame_prefix`` when set; of a fleet's fish ``--fish`` NAME: ``NAME/sim/ground_truth``
with frames ``NAME/odom``, ``NAME/base_link``) and swims with the geometry from its ROS
parameters (l1 ... drag_coefficient: the graph's one ``/**`` block of the params file,
which kinematics_node, tuner_node and planner_node read too; read at start). Without
``--ros`` it swims with ``FishGeometry``'s defaults. Fault flags: ``--corrupt-fraction``,
``--drop-fraction``, ``--stall-every/--stall-for`` (firmware freezes: no output, input lost),
``--reopen-every/--reopen-count/--reopen-delay`` (close the device, wait, open a new one).
``--calibration FILE`` (once per fish, in the order of ``--link``) keeps each fish's servo
calibration record log (SERVO_TRIM's SAVE and FACTORY) in a file: a fish_sim started again on
it boots with the saved calibration; without it the log lives in RAM.
Disturbances of the water: ``--yaw-disturbance`` (rad/s, a current that turns the fish) and
``--surge-disturbance`` (N along the body, + forward); see ``faults.Disturbance``. Faults and
disturbances apply to every fish, each fish with its own device, schedule state and
Generators (fish k, from 0: ``--seed`` + 2k for its IMU, + 2k + 1 for its faults).

Two clocks. Without ``--speed`` (the wall-clock road: benchmarks, a radio) the loop wakes every
``tick_s`` (half a telemetry period, 5 ms at 100 Hz): it reads every device, steps the physics
of every fish by the wall-clock time since the last tick, and writes what each firmware
emitted; a process behind real time drops time (``MAX_STEP_S``). A command takes effect at the
tick after it arrived (the servos' own PWM frame is 3 ms), however many fish share the process.
With ``--speed X`` (the simulated-time road of `wirefish up --sim`) the process owns the graph's
clock: it steps simulated time by ``1 / --step-hz`` (10 ms) at a time, in lockstep with the
host's SERVO_CMD stream and paced at X times real time (``max``: as fast as the graph
answers; see ``wirefish_sim.lockstep``), and with ``--ros`` publishes every step on ``clock``
(rosgraph_msgs/Clock, in its namespace: ``/wirefish/clock``), which every other node of the
graph follows as its /clock (``use_sim_time`` and a remap, ``graph.on_simulated_time``). Under
load simulated time slows down; it is never dropped. The faults' schedules run on the process's
own clock (simulated time on that road).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import fields
import math
from pathlib import Path
import select
import sys
import time
from typing import Any, NoReturn

import numpy as np

from wirefish_common.frames import frame_prefix_problem
from wirefish_common.input_checks import parse_speed, speed_text
from wirefish_common.parameter_table import InvalidParameters
from wirefish_common.shutdown import begin_teardown, exit_now, SignalShutdown
from wirefish_sim.faults import disturb, Disturbance, FaultInjector
from wirefish_sim.lockstep import clock_origin_ns, DEFAULT_GRACE_S, LockstepClock
from wirefish_sim.pty_device import PtyDevice
from wirefish_sim.servo_model import ServoParameters
from wirefish_sim.servo_trim_store import FileStorage
from wirefish_sim.virtual_fish import ImuNoise, SimConfig, VirtualFish
from wirefish_sim.virtual_fleet import VirtualFleet


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser (every option of the virtual fish is a flag)."""
    p = argparse.ArgumentParser(prog='fish_sim', description=__doc__.split('\n\n')[0])
    p.add_argument('--link', type=Path, action='append', default=None,
                   help='symlink pointing at the current pty device (e.g. /tmp/wirefish-tty); '
                   'once per fish')
    p.add_argument('--fish', action='append', default=None, metavar='NAME',
                   help='name of each fish (with several --link; default fish_1 ... fish_N): '
                   'the namespace of its sim/ground_truth and the prefix of its frames')
    p.add_argument('--ros', action='store_true', help='publish sim/ground_truth')
    p.add_argument('--ground-truth-hz', type=float, default=50.0,
                   help='rate of sim/ground_truth (Hz)')
    p.add_argument('--seed', type=int, default=0, help='seed of IMU noise and faults')
    p.add_argument('--telemetry-hz', type=float, default=100.0,
                   help='firmware: telemetry frames per second')
    p.add_argument('--heartbeat-hz', type=float, default=2.0,
                   help='firmware: heartbeats per second')
    p.add_argument('--command-timeout', type=float, default=0.5,
                   help='firmware: neutral after this long without SERVO_CMD (s)')
    p.add_argument('--heartbeat-timeout', type=float, default=1.5,
                   help='firmware: neutral after this long without a host heartbeat (s)')
    p.add_argument('--failsafe-slew', type=float, default=SimConfig.failsafe_slew_rad_s,
                   help='firmware: stream mode moves to neutral this fast (rad/s)')
    p.add_argument('--link-timeout', type=float, default=SimConfig.link_timeout_s,
                   help='firmware, gait mode: coasting after this long without a host frame '
                   '(s, 0.1-10; LINK_CONFIG changes it)')
    p.add_argument('--coast', type=float, default=SimConfig.coast_s,
                   help='firmware, gait mode: resting this long after the link timeout '
                   '(s, 0-60; LINK_CONFIG changes it)')
    p.add_argument('--servo-rate-limit', type=float,
                   default=ServoParameters.rate_limit_rad_s, help='slew limit (rad/s)')
    p.add_argument('--servo-lag', type=float, default=ServoParameters.time_constant_s,
                   help='first-order lag (s)')
    p.add_argument('--servo-update-hz', type=float, default=ServoParameters.update_hz,
                   help='servo set-point refresh rate (Hz)')
    p.add_argument('--servo-limit', type=float, default=ServoParameters.limit_rad, help='+-rad')
    p.add_argument('--imu-noise-scale', type=float, default=1.0,
                   help='factor on IMU noise and bias (0 = perfect IMU)')
    p.add_argument('--corrupt-fraction', type=float, default=0.0,
                   help='probability that an output byte is corrupted')
    p.add_argument('--drop-fraction', type=float, default=0.0,
                   help='probability that an output frame is dropped')
    p.add_argument('--stall-every', type=float, default=0.0, help='stall period (s), 0 = off')
    p.add_argument('--stall-for', type=float, default=0.0, help='stall duration (s)')
    p.add_argument('--reopen-every', type=float, default=0.0,
                   help='close and reopen the device every this many s (0 = never)')
    p.add_argument('--reopen-count', type=int, default=0, help='how many reopens (0 = no limit)')
    p.add_argument('--reopen-delay', type=float, default=0.3,
                   help='time the device is absent during a reopen (s)')
    p.add_argument('--yaw-disturbance', type=float, default=0.0,
                   help='constant yaw disturbance: the yaw rate a current gives a straight '
                   'fish (rad/s, + turns left)')
    p.add_argument('--surge-disturbance', type=float, default=0.0,
                   help='constant surge force of a current (N, + pushes forward)')
    p.add_argument('--calibration', type=Path, action='append', default=None, metavar='FILE',
                   help="file of a fish's servo calibration record log (once per fish, in "
                   '--link order; absent file: erased); without it: in RAM')
    p.add_argument('--speed', type=_speed, default=None, metavar='X',
                   help="own the clock: simulated time in lockstep with the host's SERVO_CMD, "
                   'paced at X times real time (1 = real time when the machine keeps up; max = '
                   'as fast as the host answers), published on <namespace>/clock with --ros; '
                   'absent: '
                   'the wall clock')
    p.add_argument('--step-hz', type=float, default=100.0,
                   help='with --speed: steps of simulated time per second, the rate of the '
                   "host's SERVO_CMD stream (the CPG's publish_rate_hz)")
    p.add_argument('--lockstep-grace', type=float, default=DEFAULT_GRACE_S,
                   help='with --speed: wall seconds a streaming host may keep the clock waiting '
                   'for its command before the fish stops waiting for it')
    return p


def _speed(text: str) -> float:
    """Return a --speed value (argparse type)."""
    try:
        return parse_speed(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def config_from(args: argparse.Namespace) -> SimConfig:
    """Return the SimConfig of the parsed flags."""
    return SimConfig(
        telemetry_hz=args.telemetry_hz, heartbeat_hz=args.heartbeat_hz,
        command_timeout_s=args.command_timeout, heartbeat_timeout_s=args.heartbeat_timeout,
        failsafe_slew_rad_s=args.failsafe_slew, link_timeout_s=args.link_timeout,
        coast_s=args.coast,
        servo=ServoParameters(args.servo_rate_limit, args.servo_lag, args.servo_update_hz,
                              args.servo_limit),
        imu_noise=ImuNoise().scaled(args.imu_noise_scale))


class GroundTruthPublisher:
    """
    fish_sim's ROS side, only with --ros: the geometry it swims with, and sim/ground_truth.

    The geometry (``geometry``) comes from the node's parameters, judged as kinematics_node
    judges them (``InvalidParameters`` names the first bad one); sim/ground_truth is
    nav_msgs/Odometry of each fish's state: one publisher per name of ``names`` (``''``: the
    node's own ``sim/ground_truth``; ``fish_1``: ``fish_1/sim/ground_truth``, frames
    ``fish_1/odom`` under the node's ``frame_prefix``).
    """

    def __init__(self, ros_args: list[str], names: Sequence[str] = ('',)) -> None:
        """Initialise rclpy without its signal handlers (ours stop the loop cleanly)."""
        import rclpy
        from rclpy.signals import SignalHandlerOptions
        from nav_msgs.msg import Odometry
        from wirefish_common.frames import declare_frame_prefix, prefixed
        from wirefish_common.parameter_table import NodeParameters
        from wirefish_common.qos import RELIABLE
        from wirefish_kinematics.geometry_parameters import geometry_from
        from wirefish_sim.fish_sim_parameters import TABLE

        self._rclpy = rclpy
        rclpy.init(args=ros_args, signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node('fish_sim')
        try:  # the values the other nodes of the graph judge the same way
            self._node_parameters = NodeParameters(self.node, TABLE)
        except InvalidParameters:
            self.close()
            raise
        self.geometry = geometry_from(self._node_parameters.values)
        prefix = declare_frame_prefix(self.node)  # fish_1: fish_1/odom, fish_1/base_link
        self._frames = [(prefixed(prefixed(prefix, name), 'odom'),
                         prefixed(prefixed(prefix, name), 'base_link')) for name in names]
        self._odometry = Odometry
        self.publishers = [self.node.create_publisher(
            Odometry, prefixed(name, 'sim/ground_truth'), RELIABLE) for name in names]
        self._clock_publisher: Any = None  # an rclpy Publisher once the clock is published
        # Each fish's holding nodes (its planner, its kinematics) say when their next ticks are
        # due; no executor spins this node: the lockstep loop takes the answers (``take_holds``).
        from std_msgs.msg import Header
        from wirefish_common.qos import HOLD
        from wirefish_common.topics import LOCKSTEP_HOLD_TOPIC
        self._holds = [
            self.node.create_subscription(Header, prefixed(name, LOCKSTEP_HOLD_TOPIC),
                                          _taken_not_called, HOLD)
            for name in names]

    def publish_clock(self, time_ns: int) -> None:
        """Publish ``time_ns`` on the node's ``clock`` (made at the first call)."""
        from builtin_interfaces.msg import Time
        from rosgraph_msgs.msg import Clock
        from wirefish_common.qos import CLOCK

        if self._clock_publisher is None:
            # <namespace>/clock: the graph's nodes take it as their /clock (a remap), so
            # virtual fish in namespaces of their own on one ROS domain keep their own time.
            self._clock_publisher = self.node.create_publisher(Clock, 'clock', CLOCK)
        sec, nanosec = divmod(time_ns, 1_000_000_000)
        self._clock_publisher.publish(Clock(clock=Time(sec=sec, nanosec=nanosec)))

    def take_holds(self) -> list[tuple[int, str, int]]:
        """Return (fish, holder, next tick in ns) of each answer of a holding node since."""
        answers = []
        for fish, subscription in enumerate(self._holds):
            while (taken := subscription.handle.take_message(subscription.msg_type, False)):
                stamp = taken[0].stamp
                answers.append((fish, taken[0].frame_id,
                                stamp.sec * 1_000_000_000 + stamp.nanosec))
        return answers

    def publish(self, school: Sequence[VirtualFish], time_ns: int | None = None) -> None:
        """Publish the ground truth of every fish at ``time_ns`` (None: the node clock's now)."""
        if time_ns is None:
            stamp = self.node.get_clock().now().to_msg()
        else:
            from builtin_interfaces.msg import Time
            sec, nanosec = divmod(time_ns, 1_000_000_000)
            stamp = Time(sec=sec, nanosec=nanosec)
        for fish, frames, publisher in zip(school, self._frames, self.publishers):
            s = fish.state
            msg = self._odometry()
            msg.header.stamp = stamp
            msg.header.frame_id, msg.child_frame_id = frames
            msg.pose.pose.position.x, msg.pose.pose.position.y = s.x, s.y
            msg.pose.pose.orientation.z = math.sin(s.yaw / 2.0)
            msg.pose.pose.orientation.w = math.cos(s.yaw / 2.0)
            msg.twist.twist.linear.x = s.speed
            msg.twist.twist.angular.z = s.yaw_rate
            publisher.publish(msg)

    def close(self) -> None:
        """Destroy the node (it leaves the others' graphs for good) and shut rclpy down."""
        from wirefish_common.graph_exit import destroy_leaving_the_graph
        destroy_leaving_the_graph(self.node)
        self._rclpy.try_shutdown()


def _taken_not_called(_msg: Any) -> None:
    """Never called: the lockstep loop takes the holds (``GroundTruthPublisher.take_holds``)."""


class Schedule:
    """
    Periodic fault windows: which event (if any) is active at time t (s since start).

    Event n (1, 2, ...) is due at ``n * every_s`` and lasts ``duration_s`` from when it began.
    A loop the machine starved past an event's whole window still has it, late, never skips
    it: a test that counts five reopens of the device must see five. Ask with times that never
    go back.
    """

    def __init__(self, every_s: float, duration_s: float, count: int = 0) -> None:
        """Every ``every_s`` s an event of ``duration_s`` s; at most ``count`` (0 = no limit)."""
        self.every_s, self.duration_s, self.count = every_s, duration_s, count
        self._begun = 0   # events begun so far
        self._active: int | None = None
        self._active_until = -math.inf

    def index(self, t: float) -> int | None:
        """Return the number of the event active at ``t``, or None."""
        if self._active is not None:
            if t < self._active_until:
                return self._active
            self._active = None
            return None   # once between two events, however late: a closed device reopens
        due = self._begun + 1
        if self.every_s <= 0.0 or (self.count and due > self.count) or t < due * self.every_s:
            return None
        self._begun = self._active = due
        self._active_until = t + self.duration_s
        return due


def fish_names(args: argparse.Namespace) -> list[str]:
    """Return each fish's name: ``--fish`` as given, else '' for one fish, fish_1 ... for more."""
    count = len(args.link or [None])
    if args.fish:
        return list(args.fish)
    return [''] if count == 1 else [f'fish_{i}' for i in range(1, count + 1)]


class _FishLink:
    """One fish's end of the process: its device, its faults and its reopen state."""

    def __init__(self, name: str, link: Path | None, faults: FaultInjector) -> None:
        self.name, self.device, self.faults = name, PtyDevice(link), faults
        self.reopened = 0

    def label(self) -> str:
        return f'fish_sim{f" {self.name}" if self.name else ""}'


# The most simulated time one pass of the loop integrates (s). A process behind real time (a
# starved CPU) drops the rest instead of working through it: catching up on 1 ms physics steps
# and their telemetry frames kept it behind, and deaf to a stop, for as long as the load
# lasted. At 0.05 s the scheduling delays of a loaded 2-core machine (60-100 ms passes) were
# dropped too, ~3 s in a 2-minute drive: the fish froze while the planner's clock ran on, and
# its heading hold missed its 3 deg bound (3.20 and 3.74 deg, with 3.07 and 2.98 s dropped).
MAX_STEP_S = 0.25


def loop_step(elapsed_s: float) -> tuple[float, float]:
    """Return (simulated time to integrate now, time dropped) for ``elapsed_s`` of wall time."""
    step = min(max(elapsed_s, 0.0), MAX_STEP_S)
    return step, max(elapsed_s, 0.0) - step


def run(args: argparse.Namespace, ros_args: list[str]) -> int:
    """Run the virtual fish until SIGINT/SIGTERM; return the exit code."""
    # However many SIGINT/SIGTERM arrive: one stop, exit 0 (see wirefish_common.shutdown).
    signals = SignalShutdown()
    names = fish_names(args)
    try:
        ground_truth = GroundTruthPublisher(ros_args, names) if args.ros else None
    except InvalidParameters as error:  # one line, as a node's FATAL at start-up
        print(error, file=sys.stderr, flush=True)  # it names fish_sim
        return 1
    fleet = VirtualFleet([np.random.default_rng(args.seed + 2 * k) for k in range(len(names))],
                         config_from(args),
                         ground_truth.geometry if ground_truth is not None else None,
                         [FileStorage(path) for path in args.calibration]
                         if args.calibration else None)
    print(f'fish_sim: geometry ({"ROS parameters" if ground_truth else "defaults"}) '
          + ', '.join(f'{f.name} {getattr(fleet.geometry, f.name):g}'
                      for f in fields(fleet.geometry))
          + (f'; {len(fleet)} fish: {", ".join(names)}' if len(fleet) > 1 else ''),
          file=sys.stderr, flush=True)
    links = [_FishLink(name, link, FaultInjector(np.random.default_rng(args.seed + 2 * k + 1),
                                                 args.corrupt_fraction, args.drop_fraction))
             for k, (name, link) in enumerate(zip(names, args.link or [None]))]
    disturbance = Disturbance(args.yaw_disturbance, args.surge_disturbance)
    stalls = Schedule(args.stall_every, args.stall_for)
    reopens = Schedule(args.reopen_every, args.reopen_delay, args.reopen_count)
    try:
        for link in links:
            print(link.device.open_pair(), flush=True)
        if args.speed is not None:
            _run_lockstep(args, fleet, links, disturbance, stalls, reopens, ground_truth,
                          signals)
        else:
            _run_wall_clock(args, fleet, links, disturbance, stalls, reopens, ground_truth,
                            signals)
    finally:
        begin_teardown()  # closing the devices and the ROS side must not hang the stop
        for link in links:
            link.device.close()
            link.device.remove_link()
        if ground_truth is not None:
            ground_truth.close()
    return 0


def _exchange(fleet: VirtualFleet, links: Sequence[_FishLink], closing: int | None,
              stalled: bool) -> list[int]:
    """Read every device into its fish; return the fish that received a SERVO_CMD."""
    commanded = []
    for index, (fish, link) in enumerate(zip(fleet.fish, links)):
        _reopen(link, closing)
        data = link.device.read()
        if data and not stalled:
            before = fish.commands_received
            fish.receive(data)
            if fish.commands_received != before:
                commanded.append(index)
    return commanded


def _step(fleet: VirtualFleet, links: Sequence[_FishLink], disturbance: Disturbance,
          step_s: float, stalled: bool) -> None:
    """Advance every fish by ``step_s`` of simulated time and write what each emitted."""
    fleet.step(step_s)
    for fish in fleet.fish if disturbance.active else ():
        disturb(fish.state, disturbance, step_s, fish.config.yaw_time_constant_s,
                fish.total_mass)
    for fish, link in zip(fleet.fish, links):
        output = fish.take_output()
        if link.device.is_open and not stalled and output:
            link.device.write(link.faults.apply(output))


# While the clock waits for a command, /clock is said again this often (wall s): the nodes
# take /clock best effort, and a node that missed the last one must not hold the clock.
CLOCK_REPEAT_S = 0.02
# While a holding node owes its answer the loop looks for it this often (wall s): it comes over
# DDS, which does not end the wait on the devices.
HOLD_POLL_S = 0.001


def _run_lockstep(args: argparse.Namespace, fleet: VirtualFleet, links: Sequence[_FishLink],
                  disturbance: Disturbance, stalls: Schedule, reopens: Schedule,
                  ground_truth: GroundTruthPublisher | None, signals: SignalShutdown) -> None:
    """Run on simulated time, owned by this process (``--speed``), until a stop."""
    step_ns = round(1e9 / args.step_hz)
    clock = LockstepClock(clock_origin_ns(time.time_ns(), step_ns), step_ns, args.speed,
                          len(fleet), time.monotonic(), args.lockstep_grace)
    start_ns, step_s = clock.time_ns, step_ns * 1e-9
    truth_period_ns = round(1e9 / args.ground_truth_hz)
    next_truth_ns = start_ns
    started_wall = said_wall = time.monotonic()
    if ground_truth is not None:
        ground_truth.publish_clock(clock.time_ns)
    print(f'fish_sim: simulated time from {start_ns * 1e-9:.2f} s in steps of '
          f'{step_s * 1e3:g} ms, lockstep with the host, speed {speed_text(args.speed)}',
          file=sys.stderr, flush=True)
    while not signals.requested:
        elapsed = (clock.time_ns - start_ns) * 1e-9
        closing = reopens.index(elapsed)
        stalled = stalls.index(elapsed) is not None
        for index in _exchange(fleet, links, closing, stalled):
            clock.on_command(index)
        for index, holder, next_tick_ns in ground_truth.take_holds() if ground_truth else ():
            clock.on_hold(index, holder, next_tick_ns)
        now = time.monotonic()
        engaged = list(clock.engaged)  # ready() releases a fish whose host went silent
        if clock.ready(now):
            _step(fleet, links, disturbance, step_s, stalled)
            clock.advance(now)
            _say_engagement(engaged, clock)
            if ground_truth is not None:
                ground_truth.publish_clock(clock.time_ns)
                said_wall = now
                if clock.time_ns >= next_truth_ns:
                    ground_truth.publish(fleet.fish, clock.time_ns)
                    next_truth_ns += truth_period_ns
            continue
        if ground_truth is not None and now - said_wall >= CLOCK_REPEAT_S:
            ground_truth.publish_clock(clock.time_ns)
            said_wall = now
        devices = [link.device for link in links if link.device.is_open]
        timeout = min(clock.wait_s(now), HOLD_POLL_S if clock.held_by() else CLOCK_REPEAT_S)
        if timeout > 0.0:
            select.select(devices, [], [], timeout)  # a command ends the wait at once
    counters, wall_s = clock.counters, time.monotonic() - started_wall
    simulated_s = (clock.time_ns - start_ns) * 1e-9
    print(f'fish_sim: {simulated_s:.2f} s of simulated time in {wall_s:.2f} s '
          f'(real-time factor {simulated_s / max(wall_s, 1e-9):.2f}); {counters.steps} steps, '
          f'{counters.lockstep_steps} in lockstep; the host went silent {counters.releases} '
          f'times, a holding node {counters.hold_releases}', file=sys.stderr, flush=True)


def _say_engagement(before: list[bool], clock: LockstepClock) -> None:
    """Log each fish whose host started or stopped holding the clock with this step."""
    for fish, (was, now) in enumerate(zip(before, clock.engaged)):
        if was != now:
            what = ('its host streams: simulated time waits for each command' if now else
                    f'its host was silent {clock.grace_s:g} s: simulated time follows the '
                    'wall clock')
            print(f'fish_sim: fish {fish} at simulated {clock.time_s:.2f} s: {what}',
                  file=sys.stderr, flush=True)


def _run_wall_clock(args: argparse.Namespace, fleet: VirtualFleet,
                    links: Sequence[_FishLink], disturbance: Disturbance, stalls: Schedule,
                    reopens: Schedule, ground_truth: GroundTruthPublisher | None,
                    signals: SignalShutdown) -> None:
    """Run on the wall clock (no ``--speed``) until a stop."""
    tick_s = max(0.0005, min(0.01, 1.0 / args.telemetry_hz / 2.0))
    dropped_s = 0.0
    start = last = next_tick = time.monotonic()
    next_truth = start
    while not signals.requested:
        now = time.monotonic()
        elapsed = now - start
        closing = reopens.index(elapsed)
        stalled = stalls.index(elapsed) is not None
        _exchange(fleet, links, closing, stalled)
        step_s, dropped = loop_step(now - last)
        dropped_s += dropped
        last = now
        _step(fleet, links, disturbance, step_s, stalled)
        if ground_truth is not None and now >= next_truth:
            ground_truth.publish(fleet.fish)
            next_truth = max(next_truth + 1.0 / args.ground_truth_hz, now)  # no backlog
        # One wake-up per tick for every fish, whatever the host writes in between.
        next_tick = max(next_tick + tick_s, now)
        time.sleep(max(0.0, next_tick - time.monotonic()))
    if dropped_s > 0.0:
        print(f'fish_sim: ran behind real time; {dropped_s:.2f} s of simulated time dropped',
              file=sys.stderr, flush=True)


def _reopen(link: _FishLink, closing: int | None) -> None:
    """Close or reopen ``link``'s device as the reopen schedule says now."""
    if closing is not None and link.device.is_open:
        link.device.close()
        print(f'{link.label()}: device closed (reopen {closing})', file=sys.stderr, flush=True)
    elif closing is None and not link.device.is_open:
        path = link.device.open_pair()
        link.reopened += 1
        print(f'{link.label()}: reopened as {path} ({link.reopened})', file=sys.stderr,
              flush=True)


def main(argv: list[str] | None = None) -> NoReturn:
    """Entry point: split off --ros-args, parse the flags, run; exit with its code."""
    argv = list(sys.argv if argv is None else argv)
    ros_args = argv
    try:
        from rclpy.utilities import remove_ros_args
        plain = remove_ros_args(argv)[1:]
    except ImportError:
        plain = argv[1:]
    parser = build_parser()
    args = parser.parse_args(plain)
    problem = flags_problem(args)
    if problem is not None:
        parser.error(problem)  # one line and exit code 2, before a device is opened
    exit_now(run(args, ros_args))  # no interpreter finalisation on the way out


def flags_problem(args: argparse.Namespace) -> str | None:
    """Return why the flags cannot make a virtual fish, or None."""
    for name in ('ground_truth_hz', 'telemetry_hz', 'heartbeat_hz',
                 'command_timeout', 'heartbeat_timeout', 'step_hz', 'lockstep_grace',
                 'failsafe_slew'):
        value = getattr(args, name)
        if not (math.isfinite(value) and value > 0.0):
            return f'--{name.replace("_", "-")} must be finite and > 0, got {value}'
    for name, low, high in (('link_timeout', 0.1, 10.0), ('coast', 0.0, 60.0)):
        value = getattr(args, name)  # LINK_CONFIG's ranges
        if not low <= value <= high:
            return f'--{name.replace("_", "-")} must be in [{low:g}, {high:g}] s, got {value}'
    for name in ('corrupt_fraction', 'drop_fraction'):
        value = getattr(args, name)
        if not 0.0 <= value <= 1.0:
            return f'--{name.replace("_", "-")} must be in [0, 1], got {value}'
    for name in ('imu_noise_scale', 'stall_every', 'stall_for', 'reopen_every', 'reopen_delay'):
        value = getattr(args, name)
        if not (math.isfinite(value) and value >= 0.0):
            return f'--{name.replace("_", "-")} must be finite and >= 0, got {value}'
    for name in ('yaw_disturbance', 'surge_disturbance'):
        value = getattr(args, name)
        if not math.isfinite(value):
            return f'--{name.replace("_", "-")} must be finite, got {value}'
    links = args.link or [None]
    if len(links) > 1 and None in links:
        return 'every fish of several needs its --link'
    if len({str(link) for link in links}) < len(links):
        return 'each fish needs a --link of its own'
    if args.calibration is not None and len(args.calibration) != len(links):
        return f'{len(args.calibration)} --calibration files for {len(links)} fish (--link)'
    if args.fish is not None:
        if len(args.fish) != len(links):
            return f'{len(args.fish)} --fish names for {len(links)} fish (--link)'
        for name in args.fish:
            problem = frame_prefix_problem(name)
            if problem is not None or not name:
                return f'--fish {name!r}: a name of letters, digits and _ (e.g. fish_1)'
        if len(set(args.fish)) < len(args.fish):
            return 'each fish needs a name of its own (--fish)'
    try:
        config_from(args)
    except ValueError as error:  # the servo model's own checks
        return str(error)
    return None


if __name__ == '__main__':
    raise SystemExit(main())
