"""
A register-level MPU6050 on an I2C bus, from the register map (RM-MPU-6000A-00 rev 4.2).

What the firmware's driver touches is modelled as the part does it: address 0x68 (AD0 low;
any other address NACKs), a register pointer set by the first written byte that
auto-increments on every further byte written or read, WHO_AM_I (0x75) = 0x68, PWR_MGMT_1
(0x6B) = 0x40 at reset (SLEEP: the data registers hold 0 until it is cleared), GYRO_CONFIG
(0x1B) and ACCEL_CONFIG (0x1C) FS_SEL / AFS_SEL in bits 4:3 (131 / 2^FS_SEL LSB per deg/s,
16384 / 2^AFS_SEL LSB per g), data from ACCEL_XOUT_H (0x3B): accel x, y, z, temperature, gyro
x, y, z, each big-endian two's complement. The sensor holds its true specific force (m/s^2)
and rate (rad/s) in its own axes, or raw counts set directly.
"""

from __future__ import annotations

import math

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


def _saturate(value: float) -> int:
    return max(-32768, min(32767, round(value)))


class Mpu6050Model:
    """The sensor's registers and its physical input (sensor axes, SI)."""

    def __init__(self) -> None:
        """Power-up state: asleep, full scales 0, at rest with nothing applied."""
        self.registers = bytearray(128)
        self.registers[WHO_AM_I] = 0x68
        self.registers[PWR_MGMT_1] = SLEEP
        self.pointer = 0
        self.accel_m_s2 = (0.0, 0.0, 0.0)
        self.gyro_rad_s = (0.0, 0.0, 0.0)
        self.raw_override: tuple[tuple[int, int, int], tuple[int, int, int]] | None = None
        self.transfers = 0

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
        accel = tuple(_saturate(a * self.accel_lsb_per_m_s2()) for a in self.accel_m_s2)
        gyro = tuple(_saturate(g * self.gyro_lsb_per_rad_s()) for g in self.gyro_rad_s)
        return accel, gyro  # type: ignore[return-value]

    def _refresh_data(self) -> None:
        asleep = self.registers[PWR_MGMT_1] & SLEEP
        accel, gyro = ((0, 0, 0), (0, 0, 0)) if asleep else self.raw()
        for base, values in ((ACCEL_XOUT_H, accel), (GYRO_XOUT_H, gyro)):
            for i, value in enumerate(values):
                self.registers[base + 2 * i:base + 2 * i + 2] = (value & 0xFFFF).to_bytes(2, 'big')
        self.registers[TEMP_OUT_H:TEMP_OUT_H + 2] = (0 if asleep else 1530).to_bytes(2, 'big')

    def transfer(self, address: int, tx: bytes, rx_len: int) -> bytes | None:
        """Do one I2C transaction: write ``tx``, then read ``rx_len``; None is a NACK."""
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
