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

from dataclasses import dataclass, field
import math

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
        self.servos = (Servo(c.servo), Servo(c.servo))
        self.target = (0.0, 0.0)
        self.status = Status.FAILSAFE_COMMAND | Status.FAILSAFE_HEARTBEAT
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
        self._crc_errors_reported = 0
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
        crc_errors = self.decoder.stats.crc_errors
        if crc_errors > self._crc_errors_reported:
            self._crc_errors_reported = crc_errors
            self._outbox.append(self.encoder.encode(ErrorReport(ErrorCode.BAD_CRC, 0)))

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
        c, now = self.config, self.state.time_s
        status = self.status & ~(Status.FAILSAFE_COMMAND | Status.FAILSAFE_HEARTBEAT
                                 | Status.SERVO_CLAMPED | Status.LOW_BATTERY
                                 | Status.VERSION_MISMATCH)
        if c.command_timeout_s is not None and (
                self._last_command_time is None
                or now - self._last_command_time > c.command_timeout_s):
            status |= Status.FAILSAFE_COMMAND
        if c.heartbeat_timeout_s is not None and (
                self._last_heartbeat_time is None
                or now - self._last_heartbeat_time > c.heartbeat_timeout_s):
            status |= Status.FAILSAFE_HEARTBEAT
        if not self._host_version_ok:
            status |= Status.VERSION_MISMATCH
        failsafe = status & (Status.FAILSAFE_COMMAND | Status.FAILSAFE_HEARTBEAT
                             | Status.VERSION_MISMATCH)
        self.target = (0.0, 0.0) if failsafe else self._commanded
        limit = c.servo.limit_rad
        if any(abs(a) > limit for a in self.target):
            status |= Status.SERVO_CLAMPED
        if self.battery_voltage() < c.low_battery_v:
            status |= Status.LOW_BATTERY
        self.status = status

    # --- physics ----------------------------------------------------------------------------
    def step(self, dt: float) -> None:
        """Advance simulated time by ``dt`` s in fixed physics steps (the rest is carried)."""
        self._remainder += dt
        h = self.config.physics_dt_s
        count = int(self._remainder / h + 1e-9)
        if count <= 0:
            return
        self._remainder -= count * h
        # A block of servo steps first (they do not depend on the speed), then the tail
        # kinematics for the whole block at once, then the surge/yaw integration step by step.
        angles = np.empty((count, 2))
        rates = np.empty((count, 2))
        for i in range(count):
            self._update_failsafe()
            for j, servo in enumerate(self.servos):
                servo.step(self.target[j], h)
                angles[i, j], rates[i, j] = servo.angle, servo.rate
            self.state.time_s += h
            self._emit_due(angles[i])
        velocity, slope, k1, k2 = reactive_state(angles, rates, self.geometry)
        tip = tail_tip_lateral_positions(angles, self.geometry)
        # Rates of the tail's lateral momentum terms by differences between physics steps
        # (their sum over a period telescopes to zero, as the exact mean does).
        first = self._last_momentum or (float(k1[0]), float(k2[0]))
        k1_rate = np.diff(k1, prepend=first[0]) / h
        k2_rate = np.diff(k2, prepend=first[1]) / h
        self._last_momentum = (float(k1[-1]), float(k2[-1]))
        self._integrate(velocity, slope, tip, k1_rate, k2, k2_rate, h)

    def _integrate(self, velocity: np.ndarray, slope: np.ndarray, tip: np.ndarray,
                   k1_rate: np.ndarray, k2: np.ndarray, k2_rate: np.ndarray,
                   h: float) -> None:
        s, c, g = self.state, self.config, self.geometry
        for v, dydq, y_tip, dk1, mass_k2, dk2 in zip(
                velocity.tolist(), slope.tolist(), tip.tolist(), k1_rate.tolist(),
                k2.tolist(), k2_rate.tolist()):
            thrust = float(instantaneous_thrust(v, dydq, s.speed, g))
            drag = float(drag_force(s.speed, g))
            s.acceleration = surge_acceleration(thrust, dk1, mass_k2, dk2, s.speed, drag,
                                                self.total_mass)
            s.speed += s.acceleration * h
            s.yaw_rate += h * yaw_acceleration(s.yaw_rate, y_tip, s.speed, c.yaw_gain,
                                               c.yaw_time_constant_s, g.body_length)
            s.yaw = wrap_angle(s.yaw + s.yaw_rate * h)
            s.x += s.speed * math.cos(s.yaw) * h
            s.y += s.speed * math.sin(s.yaw) * h
            s.tail_tip_offset = y_tip

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
                Heartbeat(PROTOCOL_VERSION, Role.FISH, int(now * 1000.0))))

    def telemetry(self, servo_angles: np.ndarray | None = None) -> Telemetry:
        """Return the telemetry message of now: the IMU model applied to the ground truth."""
        s, noise, rng = self.state, self.config.imu_noise, self.rng
        if servo_angles is None:
            servo_angles = np.array([servo.angle for servo in self.servos])
        attitude = rng.normal(0.0, noise.attitude_rad, 3)
        gyro = np.array([0.0, 0.0, s.yaw_rate]) + self._gyro_bias + rng.normal(
            0.0, noise.gyro_rad_s, 3)
        # Specific force in FLU: surge acceleration on x, centripetal U r on y, gravity on z.
        accel = np.array([s.acceleration, s.speed * s.yaw_rate, GRAVITY]) + self._accel_bias \
            + rng.normal(0.0, noise.accel_m_s2, 3)
        return Telemetry(board_time_ms=int(s.time_s * 1000.0) & 0xFFFFFFFF,
                         roll=float(attitude[0]), pitch=float(attitude[1]),
                         yaw=wrap_angle(s.yaw + float(attitude[2])),
                         gyro=tuple(gyro.tolist()), accel=tuple(accel.tolist()),
                         servo_1=float(servo_angles[0]), servo_2=float(servo_angles[1]),
                         battery_v=self.battery_voltage(), status=int(self.status))

    def take_output(self) -> list[bytes]:
        """Return and clear the encoded frames emitted since the last call, in order."""
        frames, self._outbox = self._outbox, []
        return frames
