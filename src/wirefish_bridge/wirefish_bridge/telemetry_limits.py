# SPDX-License-Identifier: Apache-2.0
"""
What the fish's board can physically report: one table of limits, one check (pure, no rclpy).

The codec already refuses non-finite floats; a frame that passes its CRC with a finite but
impossible value (a firmware bug, a sensor read gone wrong, a forged frame) would otherwise be
published as a measurement. Every field the firmware reports has a limit here, and why.
Limits are inclusive. ``ANGLE_SLACK_RAD`` lets an angle wrapped to exactly +-pi (or a pitch
of exactly +-pi/2) through after the firmware rounds it to float32 (float32(pi) > pi by 9e-8).
TELEMETRY_COMPACT is judged on its expanded values with half a count more on every limit (the
fish rounds to the nearest count: pi is 31416 counts of 1e-4 rad, 7e-6 rad beyond pi).
The status bits must also agree with each other and with the gait id: COASTING and RESTING
only in gait mode and never both, and a gait id exactly in gait mode (an accepted GAIT's id is
never 0).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
import math

from wirefish_bridge.protocol import (ACCEL_LSB_M_S2, ANGLE_LSB_RAD, BATTERY_LSB_V,
                                      RATE_LSB_RAD_S, Status, Telemetry, TelemetryCompact)

ANGLE_SLACK_RAD = 1e-6
# MPU6050 (section 2.1 of the paper): its widest full-scale ranges are +-2000 deg/s and +-16 g;
# the sensor cannot report beyond them.
GYRO_FULL_SCALE_RAD_S = math.radians(2000.0)
ACCEL_FULL_SCALE_M_S2 = 16.0 * 9.80665
# The servos' mechanical end stops are at +-pi/2 (the virtual fish's ServoParameters.limit_rad;
# the reel of a 180-degree servo); 0.1 rad more covers position-sensor error and horn backlash.
SERVO_MEASURED_LIMIT_RAD = math.pi / 2 + 0.1
# The battery (control cabin, section 2.1) is a 2S LiPo: 8.4 V fully charged (the virtual fish
# starts at 8.2 V, warns below 6.6 V); 9.0 V leaves room for the ADC's error. 0 V is possible
# (sense line unplugged); below 0 is not.
BATTERY_MAX_V = 9.0
KNOWN_STATUS_BITS = int(sum(flag for flag in Status if flag))


@dataclass(frozen=True)
class Limit:
    """Inclusive range of one telemetry field (its unit in ``unit``) and why it is so."""

    low: float
    high: float
    unit: str
    why: str


LIMITS: dict[str, Limit] = {
    'roll': Limit(-math.pi - ANGLE_SLACK_RAD, math.pi + ANGLE_SLACK_RAD, 'rad',
                  'ZYX Euler roll is defined on [-pi, pi]'),
    'pitch': Limit(-math.pi / 2 - ANGLE_SLACK_RAD, math.pi / 2 + ANGLE_SLACK_RAD, 'rad',
                   'ZYX Euler pitch is defined on [-pi/2, pi/2]'),
    'yaw': Limit(-math.pi - ANGLE_SLACK_RAD, math.pi + ANGLE_SLACK_RAD, 'rad',
                 'ZYX Euler yaw is defined on [-pi, pi]'),
    'gyro': Limit(-GYRO_FULL_SCALE_RAD_S, GYRO_FULL_SCALE_RAD_S, 'rad/s',
                  'MPU6050 full scale +-2000 deg/s'),
    'accel': Limit(-ACCEL_FULL_SCALE_M_S2, ACCEL_FULL_SCALE_M_S2, 'm/s^2',
                   'MPU6050 full scale +-16 g'),
    'servo': Limit(-SERVO_MEASURED_LIMIT_RAD, SERVO_MEASURED_LIMIT_RAD, 'rad',
                   'mechanical end stops +-pi/2, + 0.1 rad sensor error'),
    'battery_v': Limit(0.0, BATTERY_MAX_V, 'V', '2S LiPo, 8.4 V full, + ADC error'),
}


# Half a count of TELEMETRY_COMPACT per limit: what the fish's rounding may add.
COMPACT_SLACK: dict[str, float] = {
    'roll': ANGLE_LSB_RAD / 2, 'pitch': ANGLE_LSB_RAD / 2, 'yaw': ANGLE_LSB_RAD / 2,
    'gyro': RATE_LSB_RAD_S / 2, 'accel': ACCEL_LSB_M_S2 / 2, 'servo': ANGLE_LSB_RAD / 2,
    'battery_v': BATTERY_LSB_V / 2,
}


def _fields(telemetry: Telemetry) -> Iterator[tuple[str, str, float]]:
    """Yield (field name, limit name, value) of every range-checked float."""
    yield 'roll', 'roll', telemetry.roll
    yield 'pitch', 'pitch', telemetry.pitch
    yield 'yaw', 'yaw', telemetry.yaw
    for axis, value in zip('xyz', telemetry.gyro):
        yield f'gyro.{axis}', 'gyro', value
    for axis, value in zip('xyz', telemetry.accel):
        yield f'accel.{axis}', 'accel', value
    yield 'servo_1', 'servo', telemetry.servo_1
    yield 'servo_2', 'servo', telemetry.servo_2
    yield 'battery_v', 'battery_v', telemetry.battery_v


def telemetry_problem(telemetry: Telemetry | TelemetryCompact) -> str | None:
    """
    Return why ``telemetry`` (either form) cannot be a measurement (the first reason), or None.

    Board time may be any u32 (it wraps); status may carry only the bits PROTOCOL.md defines,
    in combinations the fish can be in.
    """
    slack: dict[str, float] = {}
    if isinstance(telemetry, TelemetryCompact):
        telemetry, slack = telemetry.expanded(), COMPACT_SLACK
    for name, limit_name, value in _fields(telemetry):
        limit = LIMITS[limit_name]
        extra = slack.get(limit_name, 0.0)
        if not limit.low - extra <= value <= limit.high + extra:
            return (f'{name} = {value:.6g} {limit.unit} outside [{limit.low:.6g}, '
                    f'{limit.high:.6g}] ({limit.why})')
    return status_problem(telemetry.status, telemetry.gait_id)


def status_problem(status: int, gait_id: int) -> str | None:
    """Return why ``status`` with ``gait_id`` is no state of the fish, or None."""
    unknown = status & ~KNOWN_STATUS_BITS
    if unknown:
        return f'status 0x{status:04x} has undefined bits 0x{unknown:04x}'
    gait_mode = bool(status & Status.GAIT_MODE)
    gap = status & (Status.COASTING | Status.RESTING)
    if gap and not gait_mode:
        return f'status 0x{status:04x}: coasting or resting outside gait mode'
    if gap == Status.COASTING | Status.RESTING:
        return f'status 0x{status:04x}: coasting and resting at once'
    if gait_mode != (gait_id != 0):
        return (f'gait_id {gait_id} with GAIT_MODE {"set" if gait_mode else "clear"} (a gait '
                'runs exactly in gait mode)')
    return None
