# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the firmware tests: the host build (made once per worker) and its C API."""

from collections.abc import Iterator

from firmware_host import build_firmware, FirmwareHost
from mpu6050_model import Mpu6050Model
import pytest


@pytest.fixture(scope='session')
def firmware_build() -> None:
    """Build the host port, the C unit tests and the sanitized fuzz driver (once: make)."""
    build_firmware('host', 'fuzz', 'build/asan/test_core')


@pytest.fixture(scope='session')
def host_lib(firmware_build: None) -> FirmwareHost:
    """Return the host build's C API (one board per process)."""
    return FirmwareHost()


@pytest.fixture
def board(host_lib: FirmwareHost) -> Iterator[FirmwareHost]:
    """Yield the board, reset to the defaults with no I2C device; no device after the test."""
    host_lib.reset()
    yield host_lib
    host_lib.reset()


@pytest.fixture
def mpu() -> Mpu6050Model:
    """Return an MPU6050 at power-up."""
    return Mpu6050Model()
