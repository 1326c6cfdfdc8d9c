# SPDX-License-Identifier: Apache-2.0
"""
A register-level MPU6050 on an I2C bus, from the register map (RM-MPU-6000A-00 rev 4.2).

What the firmware's driver touches is modelled as the part does it: address 0x68 (AD0 low;
any other address NACKs), a register pointer set by the first written byte that
auto-increments on every further byte written or read, WHO_AM_I (0x75) = 0x68, PWR_MGMT_1
(0x6B) = 0x40 at reset (SLEEP: the data registers hold 0 until it is cleared), GYRO_CONFIG
(0x1B) and ACCEL_CONFIG (0x1C) FS_SEL / AFS_SEL in bits 4:3 (131 / 2^FS_SEL LSB per deg/s,
16384 / 2^AFS_SEL LSB per g), data from ACCEL_XOUT_H (0x3B): accel x, y, z, temperature, gyro
x, y, z, each big-endian two's complement. The sensor holds its true specific force (m/s^2)
and rate (rad/s) in its own axes, or raw counts set directly; like a real part it adds a count
of noise to each axis of every sample (none to raw counts set directly).

The faults the firmware must survive, modelled at the level it sees them:
- ``freeze``: the data registers stop changing (a sensor that stopped converting);
- ``power_cycle``: the part resets (a supply dip): every register back to its power-up value,
  asleep, its configuration lost;
- the bus: ``hold_mid_byte`` puts the part half-way through sending a byte, as a reset of the
  master in the middle of a read leaves it: it drives SDA with the byte's bits, one per SCL
  clock, until the byte and its ACK slot are clocked out and it sees a NACK (SDA released);
  ``sda_shorted`` holds SDA low from outside (a short, a part that never lets go). While SDA
  or SCL is low no transaction starts (None: the master's START fails); a START on a free
  bus ends whatever byte the part was sending. ``line`` answers the
  host port's open-drain line operations (wf_host.h) for the bus recovery, and counts the SCL
  pulses it was given.
"""

from __future__ import annotations

import math
import random

ADDRESS = 0x68
WHO_AM_I = 0x75
PWR_MGMT_1 = 0x6B
GYRO_CONFIG = 0x1B
ACCEL_CONFIG = 0x1C
ACCEL_XOUT_H = 0x3B
TEMP_OUT_H = 0x41
GYRO_XOUT_H = 0x43
SLEEP = 0x40
STANDARD_GRAVITY = 9.80665
# The host port's line operations (firmware/port/host/wf_host.h).
SCL_LOW, SCL_RELEASE, SDA_LOW, SDA_RELEASE, READ_SCL, READ_SDA, HALF_BIT = range(7)
ACK_SLOT = 8


def _saturate(value: float) -> int:
    return max(-32768, min(32767, round(value)))


class Mpu6050Model:
    """The sensor's registers and its physical input (sensor axes, SI)."""

    def __init__(self, who_am_i: int = 0x68) -> None:
        """Power-up state: asleep, full scales 0, at rest with nothing applied."""
        self.registers = bytearray(128)
        self.registers[WHO_AM_I] = who_am_i
        self.registers[PWR_MGMT_1] = SLEEP
        self.pointer = 0
        self.accel_m_s2 = (0.0, 0.0, 0.0)
        self.gyro_rad_s = (0.0, 0.0, 0.0)
        self.raw_override: tuple[tuple[int, int, int], tuple[int, int, int]] | None = None
        self.transfers = 0
        self.noise_lsb = 1
        self._noise = random.Random(6050)
        self.frozen = False
        self.sda_shorted = False
        self.master_scl = True  # released
        self.master_sda = True
        self.sending: int | None = None  # the byte the part is half-way through, or None
        self.bit = 0  # the bit it drives (0 = MSB ... 7), ACK_SLOT: SDA released for the ACK
        self.scl_pulses = 0
        self.stops = 0

    def power_cycle(self) -> None:
        """Reset the part: every register to its power-up value (asleep, full scales 0)."""
        who_am_i = self.registers[WHO_AM_I]
        self.registers[:] = bytes(128)
        self.registers[WHO_AM_I] = who_am_i
        self.registers[PWR_MGMT_1] = SLEEP
        self.frozen = False

    def hold_mid_byte(self, byte: int = 0x00, bit: int = 1) -> None:
        """Leave the part sending ``byte`` at ``bit`` (SCL low): a read cut by a reset."""
        self.sending, self.bit = byte, bit

    def sda_level(self) -> bool:
        """Return SDA's level: high unless someone pulls it low."""
        driven_low = (self.sending is not None and self.bit < ACK_SLOT
                      and not (self.sending >> (7 - self.bit)) & 1)
        return self.master_sda and not self.sda_shorted and not driven_low

    def bus_idle(self) -> bool:
        """Return True when both lines are high and the part is not in a transfer."""
        return self.master_scl and self.sda_level() and self.sending is None

    def line(self, op: int) -> int:
        """Answer one open-drain line operation of the host port's bus recovery."""
        if op == SCL_LOW:
            if self.master_scl and self.sending is not None:
                self.bit += 1  # the part shifts its next bit out after SCL falls
            self.master_scl = False
        elif op == SCL_RELEASE:
            if not self.master_scl:
                self.scl_pulses += 1
                if self.sending is not None and self.bit >= ACK_SLOT:
                    if self.sda_level():
                        self.sending = None  # NACK: the part stops sending
                    else:
                        self.bit = -1  # ACK: the part goes on with another byte
            self.master_scl = True
        elif op in (SDA_LOW, SDA_RELEASE):
            rising = op == SDA_RELEASE and not self.master_sda
            self.master_sda = op == SDA_RELEASE
            if rising and self.master_scl and self.sda_level():
                self.stops += 1  # STOP: SDA rises while SCL is high
                self.sending = None
        elif op == READ_SCL:
            return int(self.master_scl)
        elif op == READ_SDA:
            return int(self.sda_level())
        return 0

    def accel_lsb_per_m_s2(self) -> float:
        """Return the accelerometer's counts per m/s^2 at its configured full scale."""
        return 16384.0 / (1 << ((self.registers[ACCEL_CONFIG] >> 3) & 3)) / STANDARD_GRAVITY

    def gyro_lsb_per_rad_s(self) -> float:
        """Return the gyro's counts per rad/s at its configured full scale."""
        return 131.0 / (1 << ((self.registers[GYRO_CONFIG] >> 3) & 3)) * 180.0 / math.pi

    def raw(self) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
        """Return the counts the data registers show now: accel, gyro (sensor axes)."""
        if self.raw_override is not None:
            return self.raw_override
        n = self.noise_lsb

        def noisy(value: float) -> int:
            return _saturate(value + (self._noise.randint(-n, n) if n else 0))

        accel = tuple(noisy(a * self.accel_lsb_per_m_s2()) for a in self.accel_m_s2)
        gyro = tuple(noisy(g * self.gyro_lsb_per_rad_s()) for g in self.gyro_rad_s)
        return accel, gyro  # type: ignore[return-value]

    def _refresh_data(self) -> None:
        if self.frozen:
            return
        asleep = self.registers[PWR_MGMT_1] & SLEEP
        accel, gyro = ((0, 0, 0), (0, 0, 0)) if asleep else self.raw()
        for base, values in ((ACCEL_XOUT_H, accel), (GYRO_XOUT_H, gyro)):
            for i, value in enumerate(values):
                self.registers[base + 2 * i:base + 2 * i + 2] = (value & 0xFFFF).to_bytes(2, 'big')
        self.registers[TEMP_OUT_H:TEMP_OUT_H + 2] = (0 if asleep else 1530).to_bytes(2, 'big')

    def transfer(self, address: int, tx: bytes, rx_len: int) -> bytes | None:
        """Do one I2C transaction: write ``tx``, then read ``rx_len``; None is a NACK."""
        if not (self.master_scl and self.sda_level()):
            return None  # a held line: the master cannot even send its START
        self.sending = None  # a START ends whatever the part was in the middle of
        if address != ADDRESS or not tx:
            return None
        self.transfers += 1
        self.pointer = tx[0] & 0x7F
        for value in tx[1:]:
            if self.pointer not in (WHO_AM_I,) and not ACCEL_XOUT_H <= self.pointer < 0x49:
                self.registers[self.pointer] = value  # read-only registers ignore writes
            self.pointer = (self.pointer + 1) & 0x7F
        self._refresh_data()
        out = bytearray()
        for _ in range(rx_len):
            out.append(self.registers[self.pointer])
            self.pointer = (self.pointer + 1) & 0x7F
        return bytes(out)


def sensor_from_flu(vector: tuple[float, float, float], axes: tuple[int, int, int]
                    ) -> tuple[float, float, float]:
    """Return ``vector`` (imu_link, FLU) in the sensor's axes for the mounting ``axes``."""
    sensor = [0.0, 0.0, 0.0]
    for flu_axis, mapping in enumerate(axes):
        sensor[abs(mapping) - 1] = math.copysign(1.0, mapping) * vector[flu_axis]
    return sensor[0], sensor[1], sensor[2]


def specific_force_at_rest(roll: float, pitch: float) -> tuple[float, float, float]:
    """Return R^T (0, 0, g) in FLU for R = Rz(yaw) Ry(pitch) Rx(roll): what a still IMU feels."""
    g = STANDARD_GRAVITY
    return (-g * math.sin(pitch), g * math.sin(roll) * math.cos(pitch),
            g * math.cos(roll) * math.cos(pitch))
