"""
Servo model of the virtual fish.

A model assumption: the paper gives no servo data; it says the servos limited its speed grid to
3 Hz (section 5.4) and could not follow the CPG above about 5 Hz at 5 cm (Fig 11).

Each servo is a cascade, advanced in fixed steps:

1. the PWM set-point is refreshed at ``update_hz`` (333 Hz: a 3 ms servo frame) from the latest
   commanded angle, clamped to the mechanical limit, and held in between;
2. the motor slews toward the set-point at no more than ``rate_limit_rad_s`` (9.1 rad/s, see
   below);
3. the horn, reel and wires follow the motor with a first-order lag ``time_constant_s``
   (0.02 s). The reported (measured) angle and its rate are those of this last stage.

The slew limit is calibrated on the paper's 3 Hz cap (``wirefish_analysis.servo_calibration``):
the fastest gait of its grid, 9 cm at 3 Hz, commands a peak servo rate of 9.03 rad/s. The
issue's first estimate, 12 rad/s, makes the 5 cm speed curve peak at 8.5 Hz (paper: 6.5 Hz);
``--servo-rate-limit 12`` still selects it.

The cascade is what makes the tail amplitude collapse at high frequency: beyond the rate limit
the motor makes a triangle whose amplitude falls as 1/f, and the lag divides it by another
factor ~ 2 pi f tau, so the tip velocity (amplitude x f) falls and so does the speed.
"""

from __future__ import annotations

from dataclasses import dataclass
import math


@dataclass(frozen=True)
class ServoParameters:
    """Rate limit (rad/s), lag (s), PWM update rate (Hz), mechanical limit (+-rad)."""

    rate_limit_rad_s: float = 9.1  # servo_calibration: the paper's 3 Hz cap
    time_constant_s: float = 0.02
    update_hz: float = 333.0
    limit_rad: float = math.pi / 2

    def __post_init__(self) -> None:
        """Check every value is finite and > 0."""
        for name in ('rate_limit_rad_s', 'time_constant_s', 'update_hz', 'limit_rad'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f'{name} must be finite and > 0, got {value}')


def clamp_to_limit(angle: float, limit: float) -> float:
    """Return ``angle`` clamped to [-limit, limit] (rad): the mechanical end stops."""
    return min(limit, max(-limit, angle))


def slew(motor: float, setpoint: float, rate_limit: float, dt: float) -> float:
    """Return the motor angle (rad) after moving toward ``setpoint`` at <= ``rate_limit``."""
    step = rate_limit * dt
    return motor + min(step, max(-step, setpoint - motor))


def lag(output: float, motor: float, time_constant: float, dt: float) -> float:
    """Return the first-order lag's output after ``dt`` with the motor held (exact step)."""
    return motor + (output - motor) * math.exp(-dt / time_constant)


class Servo:
    """One servo: set-point held between PWM frames, slewing motor, lagging output."""

    def __init__(self, params: ServoParameters, angle: float = 0.0) -> None:
        """Start at rest at ``angle`` (rad)."""
        self.params = params
        self.setpoint = angle
        self.motor = angle
        self.angle = angle
        self.rate = 0.0
        self._until_update = 0.0

    def step(self, command: float, dt: float) -> None:
        """Advance by ``dt`` s; ``command`` (rad) is latched when a PWM frame is due."""
        p = self.params
        self._until_update -= dt
        if self._until_update <= 0.0:
            self.setpoint = clamp_to_limit(command, p.limit_rad)
            self._until_update += 1.0 / p.update_hz
        self.motor = slew(self.motor, self.setpoint, p.rate_limit_rad_s, dt)
        previous = self.angle
        self.angle = lag(self.angle, self.motor, p.time_constant_s, dt)
        # The mean rate over the step (exact for the step taken, also when tau << dt).
        self.rate = (self.angle - previous) / dt
