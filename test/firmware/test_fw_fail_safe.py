# SPDX-License-Identifier: Apache-2.0
"""
The firmware's fail-safe parts on the host port: the reset path, servo limits, a checked IMU.

The host port models what the stm32f4 port does and QEMU 7.2 cannot show (it models neither
RCC_CSR nor the IWDG): the reset flags a boot reads, the fault record that survives a reset,
the fault handler's neutral compares (wf_host.h). The IMU runs against the register-level
MPU6050 model (test/support/mpu6050_model.py) with its faults: a bus held low by a read cut
mid-byte or by a short, frozen data, a sensor reset; the bus recovery is the one both ports run
(wf/i2c_bus.h), driven here through the model's open-drain lines.

Bounds, in the firmware's own terms: a stuck sensor is flagged within STUCK_SAMPLES samples
(WF_MPU6050_STUCK_SAMPLES, 100 ms at 200 Hz); a sensor whose fault has ended is trusted again
within RECOVERY_MS (the core's 100 ms probe period plus one 5 ms sample period).
"""

from collections.abc import Iterator
import ctypes

from firmware_host import FirmwareHost, HealthRecord
from mpu6050_model import (ACCEL_CONFIG, GYRO_CONFIG, Mpu6050Model, PWR_MGMT_1, SLEEP,
                           WHO_AM_I)
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (ClockSource, Health, HealthFlags, Heartbeat,
                                      PROTOCOL_VERSION, ResetCause, Role, ServoCommand, Status)

IMU_PERIOD_MS = 5
STUCK_SAMPLES = 20
PROBE_PERIOD_MS = 100
RECOVERY_MS = PROBE_PERIOD_MS + IMU_PERIOD_MS
BUS_CLEAR_PULSES = 9
NEUTRAL_TICKS = 1500
# RCC_CSR's reset flags (RM0090 7.3.21; wf/fault_record.h).
BOR, PIN, POR, SFT, IWDG, WWDG, LPWR = (1 << bit for bit in range(25, 32))
FAULT_PC, FAULT_LR, FAULT_CFSR, FAULT_HFSR = 0x080005EE, 0x0800084D, 0x00010000, 0x40000000

_LINES_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_int)


class Port:
    """The host port's reset path and I2C lines (wf_host.h), around the process's one board."""

    def __init__(self, board: FirmwareHost) -> None:
        self.board = board
        lib = board.lib
        for name, argtypes in {
            'wf_host_set_i2c_lines': [_LINES_FN, ctypes.c_void_p],
            'wf_host_fault': [ctypes.c_uint32] * 4,
            'wf_host_watchdog_reset': [],
            'wf_host_set_reset_flags': [ctypes.c_uint32],
            'wf_hal_health_port': [ctypes.POINTER(HealthRecord)],
            'wf_host_set_clock_source': [ctypes.c_uint8],
        }.items():
            getattr(lib, name).argtypes = argtypes
            getattr(lib, name).restype = None
        self._lines = _LINES_FN()
        self.encoder = FrameEncoder()

    def power_on(self, mpu: Mpu6050Model | None = None, config=None, t: int = 0) -> bytes:
        """Power the board up (the model on its bus and lines); return its first poll's output."""
        self.board.lib.wf_host_reset()
        return self.boot(mpu, config, t)

    def boot(self, mpu: Mpu6050Model | None = None, config=None, t: int = 0) -> bytes:
        """Start the board again without a power cycle (after a fault or a watchdog reset)."""
        lib = self.board.lib
        lib.wf_host_set_millis(t)
        self.board.set_i2c_device(mpu.transfer if mpu is not None else None)
        self._lines = _LINES_FN((lambda _c, op: mpu.line(op)) if mpu is not None else 0)
        lib.wf_host_set_i2c_lines(self._lines, None)
        lib.wf_host_board_init(ctypes.byref(config) if config is not None else None)
        self.encoder = FrameEncoder()
        return self.board.step(t)

    def health(self) -> HealthRecord:
        """Return the port's fields of the health report (wf_hal_health_port)."""
        record = HealthRecord()
        self.board.lib.wf_hal_health_port(ctypes.byref(record))
        return record

    def send(self, t: int, *messages) -> bytes:
        """Feed ``messages`` as host frames at ``t``; return the board's output of that poll."""
        return self.board.step(t, b''.join(self.encoder.encode(m) for m in messages))

    def run(self, start: int, end: int) -> bytes:
        """Poll once a millisecond over [start, end]; return all the output."""
        return b''.join(self.board.step(t) for t in range(start, end + 1))


@pytest.fixture
def port(board: FirmwareHost) -> Iterator[Port]:
    """Yield the host port's controls; the board is powered off (reset) afterwards."""
    yield Port(board)
    board.lib.wf_host_set_i2c_lines(_LINES_FN(), None)


def healths(output: bytes) -> list[Health]:
    """Return the HEALTH messages in the board's output."""
    return [f.message for f in StreamDecoder().feed(output) if isinstance(f.message, Health)]


def imu_fault(board: FirmwareHost) -> bool:
    """Return True when the board's status flags IMU_FAULT."""
    return bool(board.snapshot().status & Status.IMU_FAULT)


# --- the reset path ----------------------------------------------------------------------
def test_a_power_on_is_reported_as_such(port: Port):
    first = healths(port.power_on())
    assert [h.reset_cause for h in first] == [ResetCause.POWER_ON]
    assert not first[0].flags & HealthFlags.FAULT_RECORD


def test_a_fault_sets_both_servos_neutral_and_the_next_boot_names_it_with_its_pc(port: Port):
    port.power_on()
    port.send(1, Heartbeat(PROTOCOL_VERSION, Role.HOST, 0), ServoCommand(0.5, -0.5))
    assert (port.board.compare(0), port.board.compare(1)) == (1818, 1182)
    port.board.lib.wf_host_fault(FAULT_PC, FAULT_LR, FAULT_CFSR, FAULT_HFSR)
    assert (port.board.compare(0), port.board.compare(1)) == (NEUTRAL_TICKS, NEUTRAL_TICKS)
    report = healths(port.boot(t=0))
    assert len(report) == 1
    health = report[0]
    assert health.reset_cause == ResetCause.FAULT and health.flags & HealthFlags.FAULT_RECORD
    assert (health.fault_pc, health.fault_lr, health.fault_cfsr, health.fault_hfsr) == (
        FAULT_PC, FAULT_LR, FAULT_CFSR, FAULT_HFSR)


def test_a_watchdog_reset_is_reported_without_a_fault_record(port: Port):
    port.power_on()
    port.board.lib.wf_host_watchdog_reset()
    health = healths(port.boot())[0]
    assert health.reset_cause == ResetCause.IWDG
    assert not health.flags & HealthFlags.FAULT_RECORD and health.fault_pc == 0


@pytest.mark.parametrize('flags, cause', [
    (POR | BOR | PIN, ResetCause.POWER_ON),
    (BOR | PIN, ResetCause.BROWN_OUT),
    (PIN, ResetCause.PIN),
    (SFT | PIN, ResetCause.SOFTWARE),
    (IWDG | PIN, ResetCause.IWDG),
    (WWDG | PIN, ResetCause.WWDG),
    (LPWR | PIN, ResetCause.LOW_POWER),
    (0, ResetCause.UNKNOWN),
])
def test_each_reset_flag_names_its_cause(port: Port, flags: int, cause: ResetCause):
    port.power_on()
    port.board.lib.wf_host_set_reset_flags(flags)
    port.boot()
    assert port.health().reset_cause == cause


def test_the_record_is_read_once_and_a_power_loss_voids_it(port: Port):
    port.power_on()
    port.board.lib.wf_host_fault(FAULT_PC, FAULT_LR, FAULT_CFSR, FAULT_HFSR)
    port.boot()
    assert port.health().reset_cause == ResetCause.FAULT
    port.board.lib.wf_host_set_reset_flags(SFT | PIN)
    port.boot()   # a later software reset is not the old fault again
    assert port.health().reset_cause == ResetCause.SOFTWARE
    assert not port.health().flags & HealthFlags.FAULT_RECORD
    port.board.lib.wf_host_fault(FAULT_PC, FAULT_LR, FAULT_CFSR, FAULT_HFSR)
    port.board.lib.wf_host_set_reset_flags(POR | BOR | PIN)
    port.boot()   # power went while the record was pending: RAM is not to be trusted
    assert port.health().reset_cause == ResetCause.POWER_ON


@pytest.mark.parametrize('source, fallback', [
    (ClockSource.HSE_PLL, False), (ClockSource.HSI_PLL, True), (ClockSource.HSI, True),
])
def test_a_clock_fallback_is_flagged_in_status_and_health(port: Port, source: ClockSource,
                                                          fallback: bool):
    port.board.lib.wf_host_reset()
    port.board.lib.wf_host_set_clock_source(source)
    output = port.boot() + port.run(1, 20)
    assert bool(port.board.snapshot().status & Status.CLOCK_FALLBACK) is fallback
    assert healths(output)[0].clock_source == source


# --- servo limits ------------------------------------------------------------------------
def _rejected(board: FirmwareHost, **changes) -> bool:
    config = board.config_defaults()
    for name, value in changes.items():
        setattr(config.servo_cal[1], name, value)
    board.reset(config)
    return bool(board.snapshot().config_rejected)


def test_the_defaults_fit_their_limits(board: FirmwareHost):
    assert not _rejected(board)


@pytest.mark.parametrize('changes', [
    {'neutral_us': 1600.0},                       # neutral + gain x limit = 2600 > 2500
    {'neutral_us': 1400.0},                       # neutral - gain x limit = 400 < 500
    {'us_per_rad': 700.0},                        # 1500 +- 1100: both sides out
    {'us_per_rad': 700.0, 'direction': -1},       # the direction changes nothing
    {'max_us': 2400.0},                           # the servo's longest pulse below the swing
    {'min_us': 600.0},                            # its shortest above it
    {'min_us': 0.0},                              # no shortest pulse
    {'min_us': 2500.0},                           # min = max
    {'max_us': 20001.0},                          # a pulse longer than the 50 Hz frame
    {'max_us': float('nan')},
    {'min_us': float('nan')},
], ids=str)
def test_a_calibration_outside_the_servo_limits_is_refused(board: FirmwareHost, changes):
    assert _rejected(board, **changes)


def test_pulses_stay_within_the_limits_at_the_mechanical_limit(port: Port):
    config = port.board.config_defaults()
    cal = config.servo_cal[0]
    cal.min_us, cal.max_us, cal.neutral_us, cal.us_per_rad = 900.0, 2100.0, 1500.0, 380.0
    port.power_on(config=config)
    assert not port.board.snapshot().config_rejected
    # 9 rad is clamped to the mechanical limit: 1500 + 380 x pi/2 = 2097 us.
    port.send(1, Heartbeat(PROTOCOL_VERSION, Role.HOST, 0), ServoCommand(9.0, 0.0))
    assert 900 <= port.board.compare(0) <= 2100 and port.board.compare(0) == 2097
    port.send(2, ServoCommand(-9.0, 0.0))
    assert port.board.compare(0) == 903


# --- the IMU: bus recovery, stuck data, sensor reset -----------------------------------------
def _first(board: FirmwareHost, start: int, end: int, predicate) -> int | None:
    """Poll each ms from ``start``; return the first time ``predicate()`` holds, else None."""
    for t in range(start, end + 1):
        board.step(t)
        if predicate():
            return t
    return None


def test_a_sensor_holding_sda_at_boot_is_released_and_read(port: Port):
    mpu = Mpu6050Model()
    mpu.hold_mid_byte(0x00, 1)   # the board reset half-way through a read of a 0 byte
    port.power_on(mpu)
    assert mpu.sending is None and 0 < mpu.scl_pulses <= BUS_CLEAR_PULSES and mpu.stops >= 1
    assert not imu_fault(port.board)
    assert port.health().i2c_bus_recoveries == 1


@pytest.mark.parametrize('byte, bit', [(0x00, 0), (0x00, 7), (0x7F, 0), (0x01, 7)])
def test_a_read_cut_mid_byte_costs_no_sample(port: Port, byte: int, bit: int):
    mpu = Mpu6050Model()
    port.power_on(mpu)
    port.run(1, 200)
    mpu.hold_mid_byte(byte, bit)
    pulses_before = mpu.scl_pulses
    assert _first(port.board, 201, 400, lambda: imu_fault(port.board)) is None
    assert mpu.sending is None and mpu.scl_pulses - pulses_before <= BUS_CLEAR_PULSES
    # A 0 bit holds SDA: the port finds the bus busy and clears it. A 1 bit leaves SDA free:
    # the next START ends the part's byte, nothing to recover.
    held = not (byte >> (7 - bit)) & 1
    assert port.health().i2c_bus_recoveries == int(held)


def test_a_shorted_sda_is_flagged_and_recovered_after_it_ends(port: Port):
    mpu = Mpu6050Model()
    port.power_on(mpu)
    port.run(1, 200)
    mpu.sda_shorted = True
    flagged = _first(port.board, 201, 400, lambda: imu_fault(port.board))
    assert flagged is not None and flagged - 200 <= IMU_PERIOD_MS
    port.run(flagged + 1, 700)
    assert imu_fault(port.board)
    mpu.sda_shorted = False
    back = _first(port.board, 701, 1000, lambda: not imu_fault(port.board))
    assert back is not None and back - 700 <= RECOVERY_MS, back
    health = port.board.health()
    assert health.imu_faults == 1 and health.imu_recoveries == 1
    assert port.health().i2c_bus_recoveries >= 1


def test_frozen_data_is_flagged_within_the_stuck_samples_and_recovered(port: Port):
    mpu = Mpu6050Model()
    port.power_on(mpu)
    port.run(1, 200)
    mpu.frozen = True
    flagged = _first(port.board, 201, 600, lambda: imu_fault(port.board))
    assert flagged is not None and flagged - 200 <= STUCK_SAMPLES * IMU_PERIOD_MS, flagged
    port.run(flagged + 1, 800)
    assert imu_fault(port.board), 'trusted again while the data are still frozen'
    mpu.frozen = False
    back = _first(port.board, 801, 1200, lambda: not imu_fault(port.board))
    assert back is not None and back - 800 <= RECOVERY_MS, back
    assert port.board.health().imu_faults == 1 and port.board.health().imu_recoveries == 1


def test_a_sensor_reset_is_noticed_and_the_sensor_configured_again(port: Port):
    mpu = Mpu6050Model()
    port.power_on(mpu)
    port.run(1, 200)
    mpu.power_cycle()   # asleep, its full scales back to 0
    flagged = _first(port.board, 201, 600, lambda: imu_fault(port.board))
    assert flagged is not None and flagged - 200 <= STUCK_SAMPLES * IMU_PERIOD_MS, flagged
    back = _first(port.board, flagged + 1, flagged + 400, lambda: not imu_fault(port.board))
    assert back is not None and back - flagged <= RECOVERY_MS, back
    assert not mpu.registers[PWR_MGMT_1] & SLEEP
    assert (mpu.registers[GYRO_CONFIG] >> 3) & 3 == 1
    assert (mpu.registers[ACCEL_CONFIG] >> 3) & 3 == 1
    assert port.board.health().imu_recoveries == 1


@pytest.mark.parametrize('who_am_i, known', [
    (0x68, True), (0x70, True), (0x71, True), (0x73, True), (0x98, True),
    (0x00, False), (0x69, False), (0x72, False), (0xFF, False),
])
def test_the_known_compatible_parts_are_accepted(port: Port, who_am_i: int, known: bool):
    mpu = Mpu6050Model(who_am_i)
    port.power_on(mpu)
    port.run(1, 50)
    assert imu_fault(port.board) is not known
    assert mpu.registers[WHO_AM_I] == who_am_i


def test_the_readme_names_every_accepted_part():
    from firmware_host import FIRMWARE
    text = (FIRMWARE / 'README.md').read_text()
    header = (FIRMWARE / 'include' / 'wf' / 'mpu6050.h').read_text()
    for part, who_am_i in [('MPU-6050', '0x68'), ('MPU-6500', '0x70'), ('MPU-9250', '0x71'),
                           ('MPU-9255', '0x73'), ('ICM-20689', '0x98')]:
        assert f'{part}' in text and who_am_i in text and who_am_i + 'u' in header, part
