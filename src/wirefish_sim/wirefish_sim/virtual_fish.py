# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish: firmware, servos, tail kinematics, Lighthill surge and a yaw model.

Surge: Lighthill's time-resolved reactive thrust with the body's mass and added mass as
inertia (``fish_dynamics``): the speed ripple and the time constant follow from the physics.

No ROS and no real time: ``step(dt)`` advances simulated time, so tests run the physics faster
than real time; ``fish_sim`` drives it from the wall clock over a pseudo-terminal. The firmware
part speaks protocol version 2 (PROTOCOL.md) by the rules of the board's C core
(firmware/src/app.c), held equal by test/firmware/test_fw_virtual_fish_parity.py: it decodes
frames (``receive``); in stream mode it drives the servos to each SERVO_CMD and slews them to
neutral at a bounded rate when commands or host heartbeats stop; in gait mode (an accepted
GAIT) it integrates eq 1 itself with ``wirefish_cpg.oscillator.CpgIntegrator`` (RK4, 1 ms
steps of its clock, from the angles stream mode held), coasts when the link is lost and comes
to rest after the coast; it answers GAIT, LINK_CONFIG and SERVO_TRIM with ACKs and emits
telemetry (full or compact), heartbeats, HEALTH and SERVO_TRIM_REPORT as encoded frames
(``take_output``).

Servo calibration (SERVO_TRIM): the firmware's pulse mapping per servo, kept in a record log
(``servo_trim_store``: in RAM, or a file that outlives the process); the physical servo is the
build's default servo, so a trimmed calibration moves the reel (``reel_setpoint``). The
telemetry's servo angles are, as ever, the modelled reel angles: after a trim they show where
the reel sits (neutral_us 1550 at a command of 0: +0.0785 rad), where the board (which has no
angle sensor) reports its commanded angle.

Clocks: a frame received at time t acts on the physics step that starts at t (its rules run
at t, as the board's poll at the end of that millisecond runs them); what the step emits is
stamped with the time at its end.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
import enum
import math

import numpy as np
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Ack, ClockSource, ErrorCode, ErrorReport, Gait, Health,
                                      Heartbeat, LinkConfig, MsgType, PROTOCOL_VERSION,
                                      ResetCause, Role, ServoCommand, SERVOS, ServoTrim, Status,
                                      Telemetry, TelemetryCompact, TelemetryForm, TrimOp)
from wirefish_cpg.oscillator import (at_rest, CpgIntegrator, CpgParameters, initial_state,
                                     OFFSET)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (drag_force, instantaneous_thrust, reactive_state,
                                           tail_tip_lateral_positions)
from wirefish_sim.fish_dynamics import (GRAVITY, surge_acceleration, wrap_angle,
                                        yaw_acceleration)
from wirefish_sim.servo_model import Servo, ServoParameters
from wirefish_sim.servo_trim_store import Calibration, RamStorage, reel_map, Storage

# The decoder's drops that an ERROR reports: one ERROR per kind seen since that kind's last
# one, with ref_seq 0 (a dropped frame's seq is not to be trusted), at most one per kind per
# _ERROR_MIN_INTERVAL_MS (a flood of garbage must not crowd the telemetry off the link). The C
# firmware has the same rule (firmware/src/app.c, report_drops);
# test/firmware/test_fw_virtual_fish_parity.py holds the two equal.
_ERROR_MIN_INTERVAL_MS = 20
_DROP_REPORTS = ((ErrorCode.BAD_CRC, ('crc_errors',)),
                 (ErrorCode.BAD_FRAME, ('cobs_errors', 'short_frames', 'overflows')),
                 (ErrorCode.UNKNOWN_TYPE, ('unknown_type',)),
                 (ErrorCode.BAD_LENGTH, ('length_errors',)),
                 (ErrorCode.COMMAND_OUT_OF_RANGE, ('invalid_payload',)))


def _whole_ms(seconds: float) -> int:
    """Return a time difference in whole milliseconds, as the firmware's clock counts it."""
    # Simulated time is a sum of 1 ms steps: a difference of two such sums is a whole number
    # of ms plus rounding of ~1e-13 s, which must not move a timeout by a millisecond.
    return round(seconds * 1000.0)


_FAILSAFE_COMMAND = int(Status.FAILSAFE_COMMAND)
_FAILSAFE_HEARTBEAT = int(Status.FAILSAFE_HEARTBEAT)
_VERSION_MISMATCH = int(Status.VERSION_MISMATCH)
_SERVO_CLAMPED = int(Status.SERVO_CLAMPED)
_LOW_BATTERY = int(Status.LOW_BATTERY)
_COASTING = int(Status.COASTING)
_RESTING = int(Status.RESTING)
_GAIT_MODE = int(Status.GAIT_MODE)
_NEUTRAL_FLAGS = _FAILSAFE_COMMAND | _FAILSAFE_HEARTBEAT | _VERSION_MISMATCH
# The flags the failsafe check leaves as they are (it sets every other one anew).
_KEPT_FLAGS = 0xFFFF & ~(_NEUTRAL_FLAGS | _SERVO_CLAMPED | _LOW_BATTERY | _COASTING | _RESTING
                         | _GAIT_MODE)
# ACKs wait in a queue of this many and leave one per millisecond, oldest first; a GAIT,
# LINK_CONFIG or SERVO_TRIM that finds it full gets none (the host resends). The board's rule
# (app.c).
ACK_QUEUE = 4
# The board's PWM frame (wf_config_defaults' servo_frame_hz, 50 Hz): a calibration's longest
# pulse must fit in it (wf_servo_cal_fits). The firmware's rule, so the build's frame, not the
# physical servo model's refresh (ServoParameters.update_hz).
SERVO_FRAME_US = 1e6 / 50
# In gait mode the firmware steps its CPG at most this many ms at once: a longer backlog (a
# stalled poll loop, see ``stall``) is dropped and the oscillator goes on from its state, a
# pause of the gait instead of a jump of its output (app_state.h's WF_CPG_MAX_LAG_MS).
CPG_MAX_LAG_MS = 5


class Gap(enum.IntEnum):
    """Where gait mode is with the link: swimming, coasting (link lost), resting (past coast)."""

    NONE = 0
    COASTING = 1
    RESTING = 2


def _cpg_parameters(gait: Gait) -> CpgParameters:
    """Return the CPG parameters (eq 1) that a GAIT carries."""
    return CpgParameters(frequency_hz=gait.frequency_hz,
                         amplitude=(gait.amplitude_1, gait.amplitude_2),
                         offset=(gait.offset_1, gait.offset_2), w12=gait.w12, w21=gait.w21,
                         phi12=gait.phi12, phi21=gait.phi21, alpha=gait.alpha)


@dataclass(frozen=True)
class ImuNoise:
    """IMU noise (white, per sample) and constant bias spread (drawn once); SI units."""

    attitude_rad: float = 0.002
    gyro_rad_s: float = 0.005
    gyro_bias_rad_s: float = 0.01
    accel_m_s2: float = 0.05
    accel_bias_m_s2: float = 0.05

    def scaled(self, factor: float) -> ImuNoise:
        """Return every value times ``factor`` (0 = a perfect IMU)."""
        return ImuNoise(*(factor * getattr(self, n) for n in self.__dataclass_fields__))


@dataclass(frozen=True)
class SimConfig:
    """
    Constants of the virtual fish; SI units, radians.

    ``mass_kg`` (3.3 kg, section 2.1) and ``added_mass_kg`` (~0.27 kg, longitudinal) make the
    surge inertia with the tail's lateral momentum share (see ``fish_dynamics``).
    ``command_timeout_s``/``heartbeat_timeout_s`` are the firmware's stream-mode failsafe
    timeouts (None: not checked, for physics runs without a host); ``failsafe_slew_rad_s`` the
    rate at which its targets then move to neutral. ``telemetry_hz``, ``health_period_s`` (0:
    only the boot report), ``link_timeout_s`` and ``coast_s`` are the link settings at boot
    (LINK_CONFIG changes them; telemetry FULL at boot); ``cpg_step_s`` is the board CPG's step.
    """

    mass_kg: float = 3.3
    added_mass_kg: float = 0.27
    yaw_gain: float = 20.0  # 3 cm tail offset at 0.3 m/s turns ~20 deg/s (assumption)
    yaw_time_constant_s: float = 0.3
    physics_dt_s: float = 0.001
    telemetry_hz: float = 100.0
    heartbeat_hz: float = 2.0
    command_timeout_s: float | None = 0.5
    heartbeat_timeout_s: float | None = 1.5
    failsafe_slew_rad_s: float = 2.0
    health_period_s: float = 2.0
    link_timeout_s: float = 1.5
    coast_s: float = 3.0
    cpg_step_s: float = 0.001
    battery_full_v: float = 8.2
    battery_drain_v_per_s: float = 2e-4
    low_battery_v: float = 6.6
    servo: ServoParameters = field(default_factory=ServoParameters)
    imu_noise: ImuNoise = field(default_factory=ImuNoise)


@dataclass
class FishState:
    """Ground truth: time (s), surge speed (m/s), yaw rate (rad/s), pose in odom (m, rad)."""

    time_s: float = 0.0
    speed: float = 0.0
    acceleration: float = 0.0
    yaw_rate: float = 0.0
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    tail_tip_offset: float = 0.0


class VirtualFish:
    """The fish's firmware and physics, advanced by ``step(dt)``."""

    def __init__(self, config: SimConfig | None = None, geometry: FishGeometry | None = None,
                 rng: np.random.Generator | None = None, storage: Storage | None = None
                 ) -> None:
        """
        Build a fish at rest; ``rng`` draws the IMU biases and noise (seedable).

        ``storage`` holds its calibration record log (None: in RAM, erased); the fish boots
        with the calibration it holds.
        """
        self.config = config or SimConfig()
        self.geometry = geometry or FishGeometry()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        c = self.config
        self.total_mass = c.mass_kg + c.added_mass_kg
        self.state = FishState()
        self.servos = Servo(c.servo, (2,))  # the pair: servo_1, servo_2
        self.target = (0.0, 0.0)
        self.status = _FAILSAFE_COMMAND | _FAILSAFE_HEARTBEAT  # Status flags, as an int
        self.decoder = StreamDecoder()
        self.encoder = FrameEncoder()
        self.commands_received = 0
        self.last_command: tuple[float, float] | None = None
        self._last_command_time: float | None = None
        self._last_heartbeat_time: float | None = None
        self._host_version_ok = True
        self._commanded = (0.0, 0.0)
        self._outbox: list[bytes] = []
        self._next_telemetry = 1.0 / self.config.telemetry_hz
        self._next_heartbeat = 0.0
        self._remainder = 0.0
        self._drops_reported = [0] * len(_DROP_REPORTS)
        self._drop_report_due_ms = [0] * len(_DROP_REPORTS)
        # Link settings (LINK_CONFIG), gait mode and the ACK queue.
        self._telemetry_period_s = 1.0 / c.telemetry_hz
        self.telemetry_form = TelemetryForm.FULL
        self._health_period_s = c.health_period_s
        self._link_timeout_ms = round(c.link_timeout_s * 1e3)
        self._coast_ms = round(c.coast_s * 1e3)
        self._next_health = 0.0  # once right after boot, then every period from then
        self._health_sent = False
        self._reschedule = False  # a LINK_CONFIG's periods start at the next emission
        # Each ACK with the servo whose SERVO_TRIM_REPORT follows it (0: none).
        self._acks: deque[tuple[Ack, int]] = deque()
        self.calibration = Calibration(storage if storage is not None else RamStorage(),
                                       c.servo.limit_rad, SERVO_FRAME_US)
        self._boot_reports: deque[int] = deque()  # servos whose boot report is still due
        self._reel_maps = ((0.0, 1.0), (0.0, 1.0))
        self._reel_identity = True
        self._update_reel_maps()
        self.acks_dropped = 0
        self.gait: Gait | None = None  # the last accepted GAIT (None in stream mode)
        self.cpg: CpgIntegrator | None = None
        self.gap = Gap.NONE
        self._cpg_start_ms = 0
        self._last_host_frame_time = 0.0
        self._last_output_ms: int | None = None
        self._last_momentum: tuple[float, float] | None = None  # K1, K2 of the last step
        self._stalled_ms = 0  # the firmware's poll loop is blocked this many more ms
        self._held_rx = bytearray()  # what came in meanwhile, for the first poll after it
        noise = c.imu_noise
        self._gyro_bias = self.rng.normal(0.0, noise.gyro_bias_rad_s, 3)
        self._accel_bias = self.rng.normal(0.0, noise.accel_bias_m_s2, 3)

    # --- firmware: input --------------------------------------------------------------------
    def receive(self, data: bytes) -> None:
        """Feed bytes from the host (any chunking); valid frames take effect now."""
        if self._stalled_ms > 0:  # they wait in the UART until the loop polls again
            self._held_rx += data
            return
        if self._held_rx:
            data, self._held_rx = bytes(self._held_rx) + data, bytearray()
        self._advance_cpg()  # to now with the parameters in force until now
        for frame in self.decoder.feed(data):
            message = frame.message
            if isinstance(message, Heartbeat):
                if message.role != Role.HOST:
                    continue  # our own heartbeat echoed back, or another fish: not a host
                self._host_version_ok = message.version == PROTOCOL_VERSION
                if not self._host_version_ok:
                    self._outbox.append(self.encoder.encode(
                        ErrorReport(ErrorCode.VERSION_MISMATCH, frame.seq)))
                    self._leave_gait_mode()
                self.heartbeat()
            elif isinstance(message, ServoCommand):
                self._host_frame()
                if self._host_version_ok:
                    self.command(message.servo_1, message.servo_2)
            elif isinstance(message, Gait):
                self._queue_ack(MsgType.GAIT, frame.seq, self.set_gait(message, frame.seq))
            elif isinstance(message, LinkConfig):
                self._queue_ack(MsgType.LINK_CONFIG, frame.seq, self.configure_link(message))
            elif isinstance(message, ServoTrim):
                result = self.trim(message)
                self._queue_ack(MsgType.SERVO_TRIM, frame.seq, result,
                                message.servo if result == 0 else 0)

    def command(self, servo_1: float, servo_2: float) -> None:
        """Register servo targets (rad) now, as a SERVO_CMD frame would (stream mode)."""
        self._host_frame()
        self._leave_gait_mode()
        self.commands_received += 1
        self.last_command = (servo_1, servo_2)
        self._commanded = (servo_1, servo_2)
        self._last_command_time = self.state.time_s
        # The board sets its outputs at each command (two in one poll both reach the PWM), so
        # a GAIT right after it in the same poll starts gait mode from this command's angles.
        self._update_failsafe()

    def heartbeat(self) -> None:
        """Register a host heartbeat, as a HEARTBEAT frame from the host would."""
        self._host_frame()
        self._last_heartbeat_time = self.state.time_s

    def set_gait(self, gait: Gait, seq: int = 0) -> int:
        """
        Apply a GAIT now as the board does; return the ACK's result (0 or an ErrorCode).

        From stream mode the CPG starts now from rest but for its offsets b_i, at the servo
        targets stream mode held (r = 0, rates 0, phases 0): the output goes on from there and
        converges to the gait through alpha, no step. In gait mode only its targets change,
        for the steps after now. A host of another version is refused (5), a gait out of range
        too (6): nothing changes.
        """
        self._host_frame()
        if not self._host_version_ok:
            return ErrorCode.VERSION_MISMATCH
        if gait.problem(self.config.servo.limit_rad) is not None:
            return ErrorCode.COMMAND_OUT_OF_RANGE
        params = _cpg_parameters(gait)
        self._advance_cpg()
        if self.cpg is None:
            self._cpg_start_ms = _whole_ms(self.state.time_s)
            start = initial_state()
            start[OFFSET] = self.target
            self.cpg = CpgIntegrator(params, step_s=self.config.cpg_step_s, state=start)
        else:
            self.cpg.set_parameters(params)
        self.gait = gait
        return 0

    def configure_link(self, config: LinkConfig) -> int:
        """Apply a LINK_CONFIG now as the board does; return the ACK's result (0, 5 or 6)."""
        self._host_frame()
        if not self._host_version_ok:
            return ErrorCode.VERSION_MISMATCH
        if config.problem() is not None:
            return ErrorCode.COMMAND_OUT_OF_RANGE
        self._telemetry_period_s = config.telemetry_period_ms * 1e-3
        self.telemetry_form = TelemetryForm(config.telemetry_form)
        self._health_period_s = config.health_period_ms * 1e-3
        self._link_timeout_ms = config.link_timeout_ms
        self._coast_ms = config.coast_ms
        self._reschedule = True
        return 0

    def trim(self, request: ServoTrim) -> int:
        """
        Judge and apply a SERVO_TRIM now as the board does; return the ACK's result.

        In PROTOCOL.md's order: a host of another version (5, READ too), a bad field or a
        calibration that does not fit the board (6), a change in gait mode (7: READ is always
        allowed), a failed storage write (8); in every refusal nothing changes. Accepted, the
        next PWM write uses it.
        """
        self._host_frame()
        if not self._host_version_ok:
            return ErrorCode.VERSION_MISMATCH
        if request.problem() is not None:
            return ErrorCode.COMMAND_OUT_OF_RANGE
        op = request.op
        cal = self.calibration.with_values(request.neutral_us, request.us_per_rad,
                                           request.direction)
        if op in (TrimOp.SET, TrimOp.SAVE) and not self.calibration.fits(cal):
            return ErrorCode.COMMAND_OUT_OF_RANGE
        if op != TrimOp.READ and self.cpg is not None:
            return ErrorCode.NOT_NOW
        if op == TrimOp.SET:
            self.calibration.set_live(request.servo, cal)
        elif op == TrimOp.SAVE and not self.calibration.save(request.servo, cal):
            return ErrorCode.STORAGE_FAILED
        elif op == TrimOp.FACTORY and not self.calibration.factory(request.servo):
            return ErrorCode.STORAGE_FAILED
        self._update_reel_maps()
        return 0

    def _update_reel_maps(self) -> None:
        cals = self.calibration.cals
        self._reel_maps = (reel_map(cals[0]), reel_map(cals[1]))
        self._reel_identity = self._reel_maps == ((0.0, 1.0), (0.0, 1.0))

    def reel_setpoint(self) -> tuple[float, float]:
        """
        Return where the reels go (rad): the firmware's targets through its pulse mapping.

        The board writes each servo's calibrated pulse of its target; the physical servo (the
        build's default) turns the reel by that pulse.
        """
        target = self.firmware_target()
        if self._reel_identity:
            return target
        (o1, g1), (o2, g2) = self._reel_maps
        return o1 + g1 * target[0], o2 + g2 * target[1]

    @property
    def gait_id(self) -> int:
        """Return the id of the gait the fish runs (0 in stream mode)."""
        return self.gait.gait_id if self.gait is not None else 0

    def _report_drops(self, now_ms: int) -> None:
        """Send one ERROR per kind of drop since that kind's last, at most one per 20 ms."""
        stats = self.decoder.stats
        for i, (code, counters) in enumerate(_DROP_REPORTS):
            count = sum(getattr(stats, name) for name in counters)
            if count != self._drops_reported[i] and now_ms >= self._drop_report_due_ms[i]:
                self._drops_reported[i] = count
                self._drop_report_due_ms[i] = now_ms + _ERROR_MIN_INTERVAL_MS
                self._outbox.append(self.encoder.encode(ErrorReport(code, 0)))

    def _queue_ack(self, kind: MsgType, seq: int, result: int, report_servo: int = 0) -> None:
        if len(self._acks) < ACK_QUEUE:
            self._acks.append((Ack(kind, seq, int(result)), report_servo))
        else:
            self.acks_dropped += 1

    def _send_ack(self) -> bool:
        """
        Send the oldest waiting ACK; a refused GAIT's ERROR (its code and seq) just before.

        An accepted SERVO_TRIM's ACK is followed by its servo's SERVO_TRIM_REPORT; return True
        when one went.
        """
        if not self._acks:
            return False
        ack, report_servo = self._acks.popleft()
        if ack.acked_type == MsgType.GAIT and ack.result != 0:
            self._outbox.append(self.encoder.encode(ErrorReport(ack.result, ack.acked_seq)))
        self._outbox.append(self.encoder.encode(ack))
        if report_servo:
            self._outbox.append(self.encoder.encode(self.calibration.report(report_servo)))
        return bool(report_servo)

    def _host_frame(self) -> None:
        """Register a valid host frame now: the link is alive; a gap ends, the gait resumes."""
        self._last_host_frame_time = self.state.time_s
        if self.gap is not Gap.NONE:
            if self.gap is Gap.RESTING and self.cpg is not None and self.gait is not None:
                self._advance_cpg()
                self.cpg.set_parameters(_cpg_parameters(self.gait))
            self.gap = Gap.NONE

    def _advance_cpg(self) -> None:
        """
        Step the CPG (gait mode) to now: one RK4 step per millisecond since gait mode began.

        At most ``CPG_MAX_LAG_MS`` steps at once: a longer backlog moves the CPG's start on by
        the excess (as the board re-bases its cpg_time), so the output pauses, never jumps.
        """
        if self.cpg is not None:
            step_s = self.config.cpg_step_s
            lag_ms = (_whole_ms(self.state.time_s) - self._cpg_start_ms
                      - round(self.cpg.time_s / step_s))
            if not 0 <= lag_ms <= CPG_MAX_LAG_MS:
                self._cpg_start_ms += lag_ms - CPG_MAX_LAG_MS
            self.cpg.advance((_whole_ms(self.state.time_s) - self._cpg_start_ms) * step_s)

    def _leave_gait_mode(self) -> None:
        self.gait, self.cpg, self.gap = None, None, Gap.NONE

    def _update_failsafe(self) -> None:
        # Plain ints: this runs every physics step of every fish (IntFlag arithmetic costs
        # several times more than the rest of the check).
        c, now = self.config, self.state.time_s
        now_ms = _whole_ms(now)
        status = self.status & _KEPT_FLAGS
        limit = c.servo.limit_rad
        if self.cpg is not None:
            # Stepped to now with the parameters in force until now; a gap's change of targets
            # acts on the steps after now.
            self._advance_cpg()
            status |= _GAIT_MODE | self._update_gap(now)
            wanted = self.cpg.output(self.cpg.time_s)[0]
        else:
            status |= self._stream_failsafe(now)
            if status & _NEUTRAL_FLAGS:
                # To neutral at a bounded slew from where the targets are, never a step; at
                # most a second's worth per update (a long pause reaches neutral anyway).
                elapsed_ms = now_ms - (self._last_output_ms if self._last_output_ms is not None
                                       else now_ms)
                step = c.failsafe_slew_rad_s * min(elapsed_ms, 1000) * 1e-3
                t1, t2 = self.target
                wanted = (t1 - min(max(t1, -step), step), t2 - min(max(t2, -step), step))
            else:
                wanted = self._commanded
        if abs(wanted[0]) > limit or abs(wanted[1]) > limit:
            status |= _SERVO_CLAMPED
        self.target = (min(max(wanted[0], -limit), limit), min(max(wanted[1], -limit), limit))
        self._last_output_ms = now_ms
        if self.battery_voltage() < c.low_battery_v:
            status |= _LOW_BATTERY
        self.status = status

    def _stream_failsafe(self, now: float) -> int:
        """Return the stream mode's neutral flags of now."""
        c, status = self.config, 0
        if c.command_timeout_s is not None and (
                self._last_command_time is None
                or _whole_ms(now - self._last_command_time) > c.command_timeout_s * 1e3):
            status |= _FAILSAFE_COMMAND
        if c.heartbeat_timeout_s is not None and (
                self._last_heartbeat_time is None
                or _whole_ms(now - self._last_heartbeat_time) > c.heartbeat_timeout_s * 1e3):
            status |= _FAILSAFE_HEARTBEAT
        if not self._host_version_ok:
            status |= _VERSION_MISMATCH
        return status

    def _update_gap(self, now: float) -> int:
        """Return gait mode's gap flags of now; past the coast the CPG's targets go to rest."""
        silent_ms = _whole_ms(now - self._last_host_frame_time)
        if silent_ms > self._link_timeout_ms + self._coast_ms:
            if self.gap is not Gap.RESTING and self.cpg is not None:
                self.cpg.set_parameters(at_rest(self.cpg.parameters))
            self.gap = Gap.RESTING
            return _RESTING
        if silent_ms > self._link_timeout_ms:
            self.gap = Gap.COASTING
            return _COASTING
        return 0

    # --- physics ----------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Advance simulated time by ``dt`` s in fixed physics steps (the rest is carried)."""
        count, self._remainder = physics_steps(self._remainder, dt, self.config.physics_dt_s)
        if count > 0:
            swim((self,), count)

    def stall(self, seconds: float) -> None:
        """
        Block the firmware's poll loop for the next ``seconds`` (whole ms) of physics steps.

        A real board's loop blocked, or an emulator descheduled by a loaded host: the
        physics goes on with the servos held at their last targets (the PWM keeps its
        compares), nothing is sent, received bytes wait; the step after the stall runs the
        board's first poll after it, its clock jumped: the CPG takes ``CPG_MAX_LAG_MS`` steps
        and drops the rest, the schedules catch up one frame of each kind per poll.
        """
        self._stalled_ms += _whole_ms(seconds)

    def firmware_target(self) -> tuple[float, float]:
        """Run the firmware's failsafe check of now; return the servo targets (rad) it sets."""
        if self._stalled_ms > 0:
            return self.target
        if self._held_rx:
            self.receive(b'')
        self._update_failsafe()
        return self.target

    def tick(self, step_s: float, servo_angles: np.ndarray) -> None:
        """End one physics step of ``step_s`` s: the clock moves on, due frames are emitted."""
        self.state.time_s += step_s
        if self._stalled_ms > 0:
            self._stalled_ms = max(self._stalled_ms - _whole_ms(step_s), 0)
            return
        self._emit_due(servo_angles)

    def battery_voltage(self) -> float:
        """Return the battery voltage (V): a slow linear discharge (model assumption)."""
        c = self.config
        return c.battery_full_v - c.battery_drain_v_per_s * self.state.time_s

    # --- firmware: output -------------------------------------------------------------------
    def _emit_due(self, servo_angles: np.ndarray) -> None:
        """Send what this millisecond's poll sends, in the board's order (PROTOCOL.md)."""
        now = self.state.time_s
        self._report_drops(_whole_ms(now))
        if self._reschedule:  # LINK_CONFIG: the new periods count from its poll
            self._reschedule = False
            self._next_telemetry = now + self._telemetry_period_s
            self._next_health = now + self._health_period_s if self._health_period_s else math.inf
        reported = self._send_ack()
        if now + 1e-9 >= self._next_telemetry:
            self._next_telemetry += self._telemetry_period_s
            telemetry = self.telemetry(servo_angles)
            self._outbox.append(self.encoder.encode(
                TelemetryCompact.from_telemetry(telemetry)
                if self.telemetry_form is TelemetryForm.COMPACT else telemetry))
        if now + 1e-9 >= self._next_heartbeat:
            self._next_heartbeat += 1.0 / self.config.heartbeat_hz
            self._outbox.append(self.encoder.encode(
                Heartbeat(PROTOCOL_VERSION, Role.FISH, round(now * 1000.0))))
        if now + 1e-9 >= self._next_health:
            base = self._next_health if self._health_sent else now
            self._next_health = base + self._health_period_s if self._health_period_s else math.inf
            if not self._health_sent:  # the boot reports: from the boot HEALTH's poll on
                self._boot_reports.extend(SERVOS)
            self._health_sent = True
            self._outbox.append(self.encoder.encode(self.health()))
        if self._boot_reports and not reported:
            # Last in the poll and one a poll, as every kind but ERROR (an ACK's report in this
            # poll puts it off): servo 1 with the boot HEALTH, servo 2 the next poll.
            self._outbox.append(self.encoder.encode(
                self.calibration.report(self._boot_reports.popleft())))

    def telemetry(self, servo_angles: np.ndarray | None = None) -> Telemetry:
        """Return the telemetry message of now: the IMU model applied to the ground truth."""
        s, noise, rng = self.state, self.config.imu_noise, self.rng
        if servo_angles is None:
            servo_angles = self.servos.angle
        attitude = rng.normal(0.0, noise.attitude_rad, 3)
        gyro = np.array([0.0, 0.0, s.yaw_rate]) + self._gyro_bias + rng.normal(
            0.0, noise.gyro_rad_s, 3)
        # Specific force in FLU: surge acceleration on x, centripetal U r on y, gravity on z.
        accel = np.array([s.acceleration, s.speed * s.yaw_rate, GRAVITY]) + self._accel_bias \
            + rng.normal(0.0, noise.accel_m_s2, 3)
        return Telemetry(board_time_ms=round(s.time_s * 1000.0) & 0xFFFFFFFF,
                         roll=float(attitude[0]), pitch=float(attitude[1]),
                         yaw=wrap_angle(s.yaw + float(attitude[2])),
                         gyro=tuple(gyro.tolist()), accel=tuple(accel.tolist()),
                         servo_1=float(servo_angles[0]), servo_2=float(servo_angles[1]),
                         battery_v=self.battery_voltage(), status=int(self.status),
                         gait_id=self.gait_id)

    def health(self) -> Health:
        """
        Return the HEALTH of now: the virtual fish's honest values.

        It started at power-on on an emulated clock, has no fault record, brown-out, clock
        security or stack to report (0 of 0 bytes), no UART, I2C bus or IMU to fail; what it
        has is its decoder's drops.
        """
        stats = self.decoder.stats
        return Health(ResetCause.POWER_ON, ClockSource.EMULATED, 0,
                      uptime_ms=round(self.state.time_s * 1000.0) & 0xFFFFFFFF,
                      rx_crc=stats.crc_errors,
                      rx_frame=stats.cobs_errors + stats.short_frames + stats.overflows,
                      rx_unknown_type=stats.unknown_type, rx_length=stats.length_errors,
                      rx_invalid=stats.invalid_payload)

    def take_output(self) -> list[bytes]:
        """Return and clear the encoded frames emitted since the last call, in order."""
        frames, self._outbox = self._outbox, []
        return frames


def physics_steps(remainder: float, dt: float, step_s: float) -> tuple[int, float]:
    """Return how many whole ``step_s`` steps ``remainder + dt`` s hold, and what is left."""
    remainder += dt
    count = int(remainder / step_s + 1e-9)
    if count <= 0:
        return 0, remainder
    return count, remainder - count * step_s


def swim(school: Sequence[VirtualFish], count: int) -> None:
    """
    Advance every fish of ``school`` by ``count`` physics steps: one clock, one physics.

    The fish share one ``SimConfig`` and one geometry (``VirtualFleet`` checks). Step by step,
    each fish's firmware sets its servo targets and every fish's servos move in one call;
    the servos do not depend on the speed, so the whole block goes first (the telemetry
    emitted within it sees the state at the block's start). Then the tail kinematics of
    every fish and step in one evaluation (``reactive_state`` over (fish, step, 2)), then the
    surge/yaw integration step by step, each step vectorised over the fish: a fish of a school
    swims as it would alone.
    """
    first = school[0]
    c, g, h = first.config, first.geometry, first.config.physics_dt_s
    servos = Servo.stacked([fish.servos for fish in school])  # (fish, 2)
    angles = np.empty((len(school), count, 2))
    rates = np.empty((len(school), count, 2))
    targets = np.empty((len(school), 2))
    for i in range(count):
        for f, fish in enumerate(school):
            targets[f] = fish.reel_setpoint()
        servos.step(targets, h)
        angles[:, i], rates[:, i] = servos.angle, servos.rate
        for f, fish in enumerate(school):
            fish.tick(h, angles[f, i])
    servos.unstack_into([fish.servos for fish in school])
    velocity, slope, k1, k2 = reactive_state(angles, rates, g)  # each (fish, step)
    tip = tail_tip_lateral_positions(angles, g)
    # Rates of the tail's lateral momentum terms by differences between physics steps
    # (their sum over a period telescopes to zero, as the exact mean does).
    last = np.array([fish._last_momentum or (k1[f, 0], k2[f, 0])
                     for f, fish in enumerate(school)])
    k1_rate = np.diff(k1, axis=1, prepend=last[:, :1]) / h
    k2_rate = np.diff(k2, axis=1, prepend=last[:, 1:]) / h
    states = [fish.state for fish in school]
    speed = np.array([s.speed for s in states])
    yaw_rate = np.array([s.yaw_rate for s in states])
    yaw = np.array([s.yaw for s in states])
    x = np.array([s.x for s in states])
    y = np.array([s.y for s in states])
    acceleration = np.array([s.acceleration for s in states])
    for i in range(count):  # sequential in time: thrust and drag depend on the speed
        thrust = instantaneous_thrust(velocity[:, i], slope[:, i], speed, g)
        acceleration = np.asarray(surge_acceleration(
            thrust, k1_rate[:, i], k2[:, i], k2_rate[:, i], speed, drag_force(speed, g),
            first.total_mass))
        speed = speed + acceleration * h
        yaw_rate = yaw_rate + h * yaw_acceleration(yaw_rate, tip[:, i], speed, c.yaw_gain,
                                                   c.yaw_time_constant_s, g.body_length)
        yaw = wrap_angle(yaw + yaw_rate * h)
        x = x + speed * np.cos(yaw) * h
        y = y + speed * np.sin(yaw) * h
    for f, (fish, s) in enumerate(zip(school, states)):
        fish._last_momentum = (float(k1[f, -1]), float(k2[f, -1]))
        s.speed, s.acceleration = float(speed[f]), float(acceleration[f])
        s.yaw_rate, s.yaw = float(yaw_rate[f]), float(yaw[f])
        s.x, s.y, s.tail_tip_offset = float(x[f]), float(y[f]), float(tip[f, -1])
