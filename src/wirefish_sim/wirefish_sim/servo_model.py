# SPDX-License-Identifier: Apache-2.0
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
uncalibrated first guess, 12 rad/s, makes the 5 cm speed curve peak at 8.5 Hz (paper: 6.5 Hz);
``--servo-rate-limit 12`` still selects it.

The cascade is what makes the tail amplitude collapse at high frequency: beyond the rate limit
the motor makes a triangle whose amplitude falls as 1/f, and the lag divides it by another
factor ~ 2 pi f tau, so the tip velocity (amplitude x f) falls and so does the speed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike

Angles = TypeVar('Angles', float, np.ndarray)


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


def clamp_to_limit(angle: Angles, limit: float) -> Angles:
    """Return ``angle`` clamped to [-limit, limit] (rad): the mechanical end stops."""
    return np.clip(angle, -limit, limit)


def slew(motor: Angles, setpoint: Angles, rate_limit: float, dt: float) -> Angles:
    """Return the motor angle (rad) after moving toward ``setpoint`` at <= ``rate_limit``."""
    step = rate_limit * dt
    return motor + np.clip(setpoint - motor, -step, step)


def lag(output: Angles, motor: Angles, time_constant: float, dt: float) -> Angles:
    """Return the first-order lag's output after ``dt`` with the motor held (exact step)."""
    return motor + (output - motor) * math.exp(-dt / time_constant)


class Servo:
    """
    Servos of one model: set-point held between PWM frames, slewing motor, lagging output.

    Each state is an array of ``shape`` (``()``: one servo; ``(2,)``: a fish's pair; ``(N,
    2)``: a school's pairs, stepped in one call). The servos of one object share their PWM
    frame instants, as the servos of one board (and of fish on one clock) do.
    """

    def __init__(self, params: ServoParameters, shape: tuple[int, ...] = ()) -> None:
        """Start at rest at 0 rad."""
        self.params = params
        self.setpoint = np.zeros(shape)
        self.motor = np.zeros(shape)
        self.angle = np.zeros(shape)
        self.rate = np.zeros(shape)
        self.until_update = 0.0

    @classmethod
    def stacked(cls, servos: Sequence[Servo]) -> Servo:
        """Return one object holding every state of ``servos`` (one model, one PWM timing)."""
        first = servos[0]
        if any(s.params != first.params or s.until_update != first.until_update
               for s in servos):
            raise ValueError('stacked servos need one model and one PWM frame timing')
        bank = cls(first.params)
        for name in _STATES:
            setattr(bank, name, np.stack([getattr(s, name) for s in servos]))
        bank.until_update = first.until_update
        return bank

    def unstack_into(self, servos: Sequence[Servo]) -> None:
        """Copy row ``i`` of every state back into ``servos[i]`` (the inverse of ``stacked``)."""
        for name in _STATES:
            rows = getattr(self, name)
            for i, servo in enumerate(servos):
                setattr(servo, name, rows[i].copy())
        for servo in servos:
            servo.until_update = self.until_update

    def step(self, command: ArrayLike, dt: float) -> None:
        """Advance by ``dt`` s; ``command`` (rad, ``shape``) is latched when a frame is due."""
        p = self.params
        self.until_update -= dt
        if self.until_update <= 0.0:
            self.setpoint = clamp_to_limit(np.asarray(command, dtype=float), p.limit_rad)
            self.until_update += 1.0 / p.update_hz
        self.motor = slew(self.motor, self.setpoint, p.rate_limit_rad_s, dt)
        previous = self.angle
        self.angle = lag(self.angle, self.motor, p.time_constant_s, dt)
        # The mean rate over the step (exact for the step taken, also when tau << dt).
        self.rate = (self.angle - previous) / dt


_STATES = ('setpoint', 'motor', 'angle', 'rate')
