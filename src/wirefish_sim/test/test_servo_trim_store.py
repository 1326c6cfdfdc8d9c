# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's servo trim store: the board's fit check, reel map and record log."""

from dataclasses import replace
import math
import struct
import zlib

import pytest
from wirefish_bridge.protocol import CalibrationSource
from wirefish_sim.servo_trim_store import (Calibration, DEFAULT, ERASE_UNIT, f32, FileStorage,
                                           fits, RamStorage, Record, RECORD_SIZE, reel_map,
                                           ServoCal, StoredServo, winning_record)

LIMIT = math.pi / 2
FRAME = 1e6 / 333.0


def test_the_build_s_default_just_fits_500_to_2500_us():
    assert fits(DEFAULT, LIMIT, FRAME)
    assert not fits(replace(DEFAULT, neutral_us=1501.0), LIMIT, FRAME)


def test_a_trim_within_the_pulse_range_fits_and_one_beyond_does_not():
    assert fits(ServoCal(1550.0, 600.0, -1, 500.0, 2500.0), LIMIT, FRAME)
    assert not fits(ServoCal(1550.0, 636.62, 1, 500.0, 2500.0), LIMIT, FRAME)
    assert not fits(ServoCal(math.nan, 600.0, 1, 500.0, 2500.0), LIMIT, FRAME)


def test_the_default_maps_the_command_to_the_reel_exactly():
    assert reel_map(DEFAULT) == (0.0, 1.0)


def test_neutral_1550_puts_the_reel_at_0_0785_rad_for_a_command_of_0():
    offset, gain = reel_map(ServoCal(1550.0, 600.0, -1, 500.0, 2500.0))
    assert offset == pytest.approx(0.0785398, rel=1e-6)
    assert gain == pytest.approx(-600.0 / 636.619772, rel=1e-6)


def test_a_record_is_36_bytes_as_the_spec_lays_it_out():
    record = Record(7, (StoredServo(1550.0, 600.0, -1, True), StoredServo()))
    data = record.encode()
    assert len(data) == RECORD_SIZE == 36
    assert data[:4] == b'WFCL'
    assert data[:32] == struct.pack('<IIffbB2xffbB2x', 0x4C434657, 7, 1550.0, 600.0, -1, 1,
                                    0.0, 0.0, 0, 0)
    assert struct.unpack('<I', data[32:])[0] == zlib.crc32(data[:32])
    assert Record.decode(data) == record


def test_a_record_with_a_flipped_bit_is_skipped_and_the_older_one_wins():
    older = Record(1, (StoredServo(1510.0, 600.0, 1, True), StoredServo()))
    newer = bytearray(Record(2, (StoredServo(1520.0, 600.0, 1, True), StoredServo())).encode())
    newer[9] ^= 0x10
    unit = older.encode() + bytes(newer) + b'\xff' * (ERASE_UNIT - 2 * RECORD_SIZE)
    best, end = winning_record(unit)
    assert best == older and end == 2 * RECORD_SIZE


def test_save_then_boot_gives_the_stored_values_and_factory_gives_the_defaults():
    storage = RamStorage()
    cal = Calibration(storage, LIMIT, FRAME)
    trimmed = cal.with_values(1550.0, 600.0, -1)
    assert cal.save(2, trimmed)
    booted = Calibration(storage, LIMIT, FRAME)
    assert booted.report(2).source is CalibrationSource.STORED
    assert booted.cals[1] == trimmed and booted.cals[0] == DEFAULT
    assert booted.factory(2)
    again = Calibration(storage, LIMIT, FRAME)
    assert again.report(2).source is CalibrationSource.DEFAULTS and again.cals[1] == DEFAULT


def test_a_full_unit_is_erased_and_the_record_goes_to_offset_0():
    storage = RamStorage()
    cal = Calibration(storage, LIMIT, FRAME)
    slots = ERASE_UNIT // RECORD_SIZE
    for k in range(slots + 1):
        assert cal.save(1, cal.with_values(1500.0 + (k % 10), 600.0, 1))
    best, end = winning_record(storage.read())
    assert end == RECORD_SIZE and best.generation == slots + 1
    assert best.servos[0].neutral_us == f32(1500.0 + slots % 10)


def test_a_failed_write_changes_nothing_not_even_live():
    storage = RamStorage()
    cal = Calibration(storage, LIMIT, FRAME)
    storage.fail = True
    assert not cal.save(1, cal.with_values(1550.0, 600.0, 1))
    assert cal.cals[0] == DEFAULT and cal.sources[0] is CalibrationSource.DEFAULTS


def test_a_stored_servo_that_no_longer_fits_boots_on_the_defaults():
    storage = RamStorage()
    storage.program(0, Record(1, (StoredServo(1600.0, 636.62, 1, True),
                                  StoredServo(1490.0, 600.0, 1, True))).encode())
    cal = Calibration(storage, LIMIT, FRAME)
    assert [s.name for s in cal.sources] == ['DEFAULTS', 'STORED']


def test_a_file_log_survives_a_new_store_and_an_absent_file_is_erased(tmp_path):
    path = tmp_path / 'calibration.bin'
    assert FileStorage(path).read() == b'\xff' * ERASE_UNIT
    cal = Calibration(FileStorage(path), LIMIT, FRAME)
    assert cal.save(1, cal.with_values(1550.0, 600.0, 1))
    assert path.stat().st_size == RECORD_SIZE
    assert Calibration(FileStorage(path), LIMIT, FRAME).sources[0] is CalibrationSource.STORED
