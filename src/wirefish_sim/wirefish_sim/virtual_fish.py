"""
The virtual fish: firmware, servos, tail kinematics, Lighthill surge and a yaw model.

Surge: Lighthill's time-resolved reactive thrust with the body's mass and added mass as
inertia (``fish_dynamics``): the speed ripple and the time constant follow from the physics.

No ROS and no real time: ``step(dt)`` advances simulated time, so tests run the physics faster
than real time; ``fish_sim`` drives it from the wall clock over a pseudo-terminal. The firmware
part decodes frames (``receive``), commands neutral when servo commands or host heartbeats stop,
and emits telemetry (100 Hz) and heartbeats as encoded frames (``take_output``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (ErrorCode, ErrorReport, Heartbeat, PROTOCOL_VERSION, Role,
                                      ServoCommand, Status, Telemetry)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.lighthill import (drag_force, instantaneous_thrust, reactive_state,
                                           tail_tip_lateral_positions)
from wirefish_sim.fish_dynamics import (GRAVITY, surge_acceleration, wrap_angle,
                                        yaw_acceleration)
from wirefish_sim.servo_model import Servo, ServoParameters

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
_NEUTRAL_FLAGS = _FAILSAFE_COMMAND | _FAILSAFE_HEARTBEAT | _VERSION_MISMATCH
# The flags the failsafe check leaves as they are (it sets every other one anew).
_KEPT_FLAGS = 0xFFFF & ~(_NEUTRAL_FLAGS | _SERVO_CLAMPED | _LOW_BATTERY)


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
    ``command_timeout_s``/``heartbeat_timeout_s`` are the firmware's
    failsafe timeouts (None: not checked, for physics runs without a host).
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
                 rng: np.random.Generator | None = None) -> None:
        """Build a fish at rest; ``rng`` draws the IMU biases and noise (seedable)."""
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
        self._last_momentum: tuple[float, float] | None = None  # K1, K2 of the last step
        noise = c.imu_noise
        self._gyro_bias = self.rng.normal(0.0, noise.gyro_bias_rad_s, 3)
        self._accel_bias = self.rng.normal(0.0, noise.accel_bias_m_s2, 3)

    # --- firmware: input --------------------------------------------------------------------
    def receive(self, data: bytes) -> None:
        """Feed bytes from the host (any chunking); valid frames take effect now."""
        for frame in self.decoder.feed(data):
            message = frame.message
            if isinstance(message, Heartbeat) and message.role == Role.HOST:
                self._host_version_ok = message.version == PROTOCOL_VERSION
                if not self._host_version_ok:
                    self._outbox.append(self.encoder.encode(
                        ErrorReport(ErrorCode.VERSION_MISMATCH, frame.seq)))
                self.heartbeat()
            elif isinstance(message, ServoCommand):
                if self._host_version_ok:
                    self.command(message.servo_1, message.servo_2)
        stats, now_ms = self.decoder.stats, _whole_ms(self.state.time_s)
        for i, (code, counters) in enumerate(_DROP_REPORTS):
            count = sum(getattr(stats, name) for name in counters)
            if count != self._drops_reported[i] and now_ms >= self._drop_report_due_ms[i]:
                self._drops_reported[i] = count
                self._drop_report_due_ms[i] = now_ms + _ERROR_MIN_INTERVAL_MS
                self._outbox.append(self.encoder.encode(ErrorReport(code, 0)))

    def command(self, servo_1: float, servo_2: float) -> None:
        """Register servo targets (rad) now, as a SERVO_CMD frame would."""
        self.commands_received += 1
        self.last_command = (servo_1, servo_2)
        self._commanded = (servo_1, servo_2)
        self._last_command_time = self.state.time_s

    def heartbeat(self) -> None:
        """Register a host heartbeat, as a HEARTBEAT frame from the host would."""
        self._last_heartbeat_time = self.state.time_s

    def _update_failsafe(self) -> None:
        # Plain ints: this runs every physics step of every fish (IntFlag arithmetic costs
        # several times more than the rest of the check).
        c, now = self.config, self.state.time_s
        status = self.status & _KEPT_FLAGS
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
        self.target = (0.0, 0.0) if status & _NEUTRAL_FLAGS else self._commanded
        limit = c.servo.limit_rad
        if abs(self.target[0]) > limit or abs(self.target[1]) > limit:
            status |= _SERVO_CLAMPED
        if self.battery_voltage() < c.low_battery_v:
            status |= _LOW_BATTERY
        self.status = status

    # --- physics ----------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Advance simulated time by ``dt`` s in fixed physics steps (the rest is carried)."""
        count, self._remainder = physics_steps(self._remainder, dt, self.config.physics_dt_s)
        if count > 0:
            swim((self,), count)

    def firmware_target(self) -> tuple[float, float]:
        """Run the firmware's failsafe check of now; return the servo targets (rad) it sets."""
        self._update_failsafe()
        return self.target

    def tick(self, step_s: float, servo_angles: np.ndarray) -> None:
        """End one physics step of ``step_s`` s: the clock moves on, due frames are emitted."""
        self.state.time_s += step_s
        self._emit_due(servo_angles)

    def battery_voltage(self) -> float:
        """Return the battery voltage (V): a slow linear discharge (model assumption)."""
        c = self.config
        return c.battery_full_v - c.battery_drain_v_per_s * self.state.time_s

    # --- firmware: output -------------------------------------------------------------------
    def _emit_due(self, servo_angles: np.ndarray) -> None:
        now = self.state.time_s
        if now + 1e-9 >= self._next_telemetry:
            self._next_telemetry += 1.0 / self.config.telemetry_hz
            self._outbox.append(self.encoder.encode(self.telemetry(servo_angles)))
        if now + 1e-9 >= self._next_heartbeat:
            self._next_heartbeat += 1.0 / self.config.heartbeat_hz
            self._outbox.append(self.encoder.encode(
                Heartbeat(PROTOCOL_VERSION, Role.FISH, round(now * 1000.0))))

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
                         battery_v=self.battery_voltage(), status=int(self.status))

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
            targets[f] = fish.firmware_target()
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
