# SPDX-License-Identifier: Apache-2.0
"""
The MPU6050 driver and the attitude filter on the host port, against a register-level model.

The model (test/support/mpu6050_model.py) answers the driver's I2C transactions as the part's
register map says. Scaling and the axis remap are exact: the values in the board (and in its
telemetry) equal, bit for bit, the counts times the full-scale factor in binary32, moved to
FLU by the mounting. The filter: a still, tilted fish reads its roll and pitch within 0.5 deg
after 5 s; a constant yaw rate integrates within 2 % over 10 s.
"""

import math

from firmware_host import FirmwareHost
from mpu6050_model import (ACCEL_CONFIG, GYRO_CONFIG, Mpu6050Model, PWR_MGMT_1,
                           sensor_from_flu, SLEEP, specific_force_at_rest)
import numpy as np
import pytest
from wirefish_bridge.codec import StreamDecoder
from wirefish_bridge.protocol import Status, Telemetry

GYRO_SCALE = np.float32(math.pi / 180.0 / 65.5)   # FS_SEL 1: 65.5 LSB per deg/s
ACCEL_SCALE = np.float32(9.80665 / 8192.0)       # AFS_SEL 1: 8192 LSB per g
DEFAULT_AXES = (2, -1, 3)  # the default mounting: sensor +Y forward, +X right, +Z up
MOUNTINGS = [DEFAULT_AXES, (1, 2, 3), (-1, -2, 3), (3, 2, -1)]
HALF_DEGREE = math.radians(0.5)


def start(board: FirmwareHost, mpu: Mpu6050Model, axes=DEFAULT_AXES) -> None:
    """Reset the board with the model on its bus and the mounting ``axes``."""
    config = board.config_defaults()
    config.imu_axes[:] = axes
    board.reset(config, i2c=mpu.transfer)


def run(board: FirmwareHost, start_ms: int, end_ms: int) -> list[bytes]:
    """Poll once a millisecond over [start_ms, end_ms]; return the output of each poll."""
    return [board.step(t) for t in range(start_ms, end_ms + 1)]


def expected_flu(raw: tuple[int, int, int], scale: np.float32, axes) -> list[float]:
    """Return the FLU values the driver must report for sensor counts ``raw``."""
    sensor = [np.float32(r) * scale for r in raw]
    return [float(math.copysign(1.0, a) * sensor[abs(a) - 1]) for a in axes]


def test_driver_wakes_the_sensor_and_sets_both_full_scales(board: FirmwareHost,
                                                           mpu: Mpu6050Model):
    start(board, mpu)
    run(board, 0, 5)
    assert not mpu.registers[PWR_MGMT_1] & SLEEP
    assert (mpu.registers[GYRO_CONFIG] >> 3) & 3 == 1
    assert (mpu.registers[ACCEL_CONFIG] >> 3) & 3 == 1
    assert not board.snapshot().status & Status.IMU_FAULT


@pytest.mark.parametrize('axes', MOUNTINGS, ids=str)
@pytest.mark.parametrize('accel_raw, gyro_raw', [
    ((1234, -20000, 8192), (-32768, 32767, 655)),
    ((-1, 0, 32767), (1, -1, -12345)),
])
def test_scaling_and_axis_remap_are_exact(board: FirmwareHost, mpu: Mpu6050Model, axes,
                                          accel_raw, gyro_raw):
    mpu.raw_override = (accel_raw, gyro_raw)
    start(board, mpu, axes)
    run(board, 0, 10)
    state = board.snapshot()
    assert tuple(state.raw_accel) == accel_raw and tuple(state.raw_gyro) == gyro_raw
    assert list(state.accel) == expected_flu(accel_raw, ACCEL_SCALE, axes)
    assert list(state.gyro) == expected_flu(gyro_raw, GYRO_SCALE, axes)


def test_telemetry_carries_the_remapped_values(board: FirmwareHost, mpu: Mpu6050Model):
    mpu.raw_override = ((100, 200, 8000), (-300, 400, 500))
    start(board, mpu)
    frames = StreamDecoder().feed(b''.join(run(board, 0, 10)))
    telemetry = [f.message for f in frames if isinstance(f.message, Telemetry)]
    assert len(telemetry) == 1
    assert list(telemetry[0].accel) == expected_flu((100, 200, 8000), ACCEL_SCALE, DEFAULT_AXES)
    assert list(telemetry[0].gyro) == expected_flu((-300, 400, 500), GYRO_SCALE, DEFAULT_AXES)


def test_absent_imu_sets_imu_fault_until_it_answers(board: FirmwareHost, mpu: Mpu6050Model):
    config = board.config_defaults()
    board.reset(config)  # nothing on the bus: every transfer NACKs
    run(board, 0, 100)
    assert board.snapshot().status & Status.IMU_FAULT
    assert list(board.snapshot().accel) == [0.0, 0.0, 0.0]
    board.set_i2c_device(mpu.transfer)
    run(board, 101, 1100)  # the driver probes again once a second
    assert not board.snapshot().status & Status.IMU_FAULT


@pytest.mark.parametrize('roll, pitch', [(0.0, 0.0), (0.3, -0.2), (-0.6, 0.4), (1.2, 0.1)])
def test_still_fish_reads_its_attitude_within_half_a_degree_after_5_s(
        board: FirmwareHost, mpu: Mpu6050Model, roll: float, pitch: float):
    mpu.accel_m_s2 = sensor_from_flu(specific_force_at_rest(roll, pitch), DEFAULT_AXES)
    start(board, mpu)
    run(board, 0, 5000)
    state = board.snapshot()
    assert abs(state.roll - roll) < HALF_DEGREE
    assert abs(state.pitch - pitch) < HALF_DEGREE
    assert abs(state.yaw) < HALF_DEGREE


@pytest.mark.parametrize('rate', [0.5, -1.5])
def test_constant_yaw_rate_integrates_within_2_percent_over_10_s(
        board: FirmwareHost, mpu: Mpu6050Model, rate: float):
    mpu.accel_m_s2 = sensor_from_flu(specific_force_at_rest(0.0, 0.0), DEFAULT_AXES)
    mpu.gyro_rad_s = sensor_from_flu((0.0, 0.0, rate), DEFAULT_AXES)
    start(board, mpu)
    yaw = []
    for t in range(0, 10_001):
        board.step(t)
        if t % 10 == 0:
            yaw.append(board.snapshot().yaw)
    turned = float(np.unwrap(np.array(yaw, dtype=float))[-1] - yaw[0])
    assert turned == pytest.approx(rate * 10.0, rel=0.02)
