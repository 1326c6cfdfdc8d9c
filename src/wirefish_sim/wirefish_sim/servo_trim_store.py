# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish's servo calibration: the board's pulse mapping, its fit check and its storage.

Pure (file I/O only in ``FileStorage``). The firmware writes a servo's PWM pulse as
``neutral_us + direction * us_per_rad * angle`` (``wf_servo_pulse_us``); a calibration is
accepted when every angle the servo limit lets through maps into ``[min_us, max_us]`` and the
range fits the servo frame (``wf_servo_cal_fits``), judged in binary32 as the board does.

The physical servo of the virtual fish is the build's default servo (``DEFAULT``: 1500 us at
0 rad, 636.62 us/rad, direction +1): it turns its reel to ``(pulse - 1500) / 636.62`` rad. A
trimmed calibration therefore moves the reel: neutral_us 1550 puts it at +0.0785 rad for a
command of 0 (``reel_map``).

Storage is the board's record log byte for byte: 36-byte records (magic ``WFCL``, generation,
per servo neutral_us f32, us_per_rad f32, direction i8, valid u8, 2 B pad, then a CRC-32 of
the first 32 B) appended in one erase unit of ``ERASE_UNIT`` bytes (erased: 0xFF); the valid
record with the highest generation wins; a full unit is erased and the record goes to offset 0.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
import os
from pathlib import Path
import struct
from typing import Protocol
import zlib

import numpy as np
from wirefish_bridge.protocol import CalibrationSource, ServoTrimReport

RECORD_MAGIC = 0x4C434657   # 'W', 'F', 'C', 'L' little-endian
ERASE_UNIT = 16 * 1024      # the STM32F407's flash sector 2
_SERVO = struct.Struct('<ffbB2x')
_HEAD = struct.Struct('<II')
_CRC = struct.Struct('<I')
RECORD_SIZE = _HEAD.size + 2 * _SERVO.size + _CRC.size
assert RECORD_SIZE == 36 and _SERVO.size == 12   # nine 32-bit words, as the board writes


def f32(value: float) -> float:
    """Return the binary32 nearest ``value``, as the board holds it."""
    return float(np.float32(value))


@dataclass(frozen=True)
class ServoCal:
    """One servo's calibration: pulse at 0 rad, us per rad, direction, the pulse range (us)."""

    neutral_us: float
    us_per_rad: float
    direction: int
    min_us: float
    max_us: float

    def binary32(self) -> ServoCal:
        """Return the calibration with its floats as the board holds them (single precision)."""
        return replace(self, neutral_us=f32(self.neutral_us), us_per_rad=f32(self.us_per_rad))


# The build's servo (firmware/src/app.c's defaults): a 180-degree hobby servo.
DEFAULT = ServoCal(1500.0, f32(636.619772), 1, 500.0, 2500.0)


def limit_binary32(limit_rad: float) -> float:
    """Return the largest binary32 not above ``limit_rad`` (the board's servo limit)."""
    value = np.float32(limit_rad)
    if float(value) > limit_rad:
        value = np.nextafter(value, np.float32(0.0))
    return float(value)


def fits(cal: ServoCal, limit_rad: float, frame_us: float) -> bool:
    """
    Return True when ``cal`` maps every angle within +-``limit_rad`` into its pulse range.

    ``wf_servo_cal_fits`` in binary32: 0 < min_us < max_us <= frame_us and neutral_us -+
    us_per_rad * limit within [min_us, max_us]; False for a NaN.
    """
    one = np.float32
    swing = one(cal.us_per_rad) * one(limit_binary32(limit_rad))
    return bool(one(cal.min_us) > 0 and one(cal.min_us) < one(cal.max_us)
                and one(cal.max_us) <= one(frame_us)
                and one(cal.neutral_us) - swing >= one(cal.min_us)
                and one(cal.neutral_us) + swing <= one(cal.max_us))


def reel_map(cal: ServoCal, physical: ServoCal = DEFAULT) -> tuple[float, float]:
    """
    Return (offset, gain): the reel sits at ``offset + gain * angle`` rad for a commanded angle.

    The board writes ``cal``'s pulse; the physical servo (``physical``'s mapping) turns the
    reel by it. With ``cal == physical`` the map is exactly (0.0, 1.0).
    """
    offset = (cal.neutral_us - physical.neutral_us) / physical.us_per_rad
    gain = cal.direction * cal.us_per_rad / (physical.direction * physical.us_per_rad)
    return offset, gain


@dataclass(frozen=True)
class StoredServo:
    """One servo's part of a record: its values, and whether they are stored (valid)."""

    neutral_us: float = 0.0
    us_per_rad: float = 0.0
    direction: int = 0
    valid: bool = False


@dataclass(frozen=True)
class Record:
    """One record of the log: its generation and both servos' parts."""

    generation: int
    servos: tuple[StoredServo, StoredServo]

    def encode(self) -> bytes:
        """Return the record's 36 bytes (CRC-32 of the first 32, as zlib.crc32)."""
        body = _HEAD.pack(RECORD_MAGIC, self.generation & 0xFFFFFFFF) + b''.join(
            _SERVO.pack(s.neutral_us, s.us_per_rad, s.direction, int(s.valid))
            for s in self.servos)
        return body + _CRC.pack(zlib.crc32(body))

    @classmethod
    def decode(cls, data: bytes) -> Record | None:
        """Return the record in ``data`` (36 bytes), or None for a bad magic, CRC or value."""
        if len(data) != RECORD_SIZE:
            return None
        magic, generation = _HEAD.unpack_from(data)
        if magic != RECORD_MAGIC or zlib.crc32(data[:-_CRC.size]) != _CRC.unpack_from(
                data, RECORD_SIZE - _CRC.size)[0]:
            return None
        servos = []
        for i in range(2):
            neutral, per_rad, direction, valid = _SERVO.unpack_from(data, _HEAD.size
                                                                    + i * _SERVO.size)
            servos.append(StoredServo(neutral, per_rad, direction, valid == 1))
        return cls(generation, (servos[0], servos[1]))


def winning_record(unit: bytes) -> tuple[Record | None, int]:
    """
    Return the log's winning record (highest generation of the valid ones) and the free offset.

    The free offset is where the next record goes: after the last slot that is not erased
    (a torn or bad record still takes its slot); ``len(unit)`` rounded down when full.
    """
    best: Record | None = None
    end = 0
    erased = b'\xff' * RECORD_SIZE
    for offset in range(0, len(unit) - RECORD_SIZE + 1, RECORD_SIZE):
        slot = unit[offset:offset + RECORD_SIZE]
        if slot == erased:
            continue
        end = offset + RECORD_SIZE
        record = Record.decode(slot)
        # A tie (which no writer makes) goes to the later record, as a later write would.
        if record is not None and (best is None or record.generation >= best.generation):
            best = record
    return best, end


class Storage(Protocol):
    """Where the record log lives: one erase unit, read whole, written by offset."""

    def read(self) -> bytes:
        """Return the unit's bytes (ERASE_UNIT of them; 0xFF where erased)."""

    def erase(self) -> bool:
        """Erase the unit; return False when it failed."""

    def program(self, offset: int, data: bytes) -> bool:
        """Write ``data`` at ``offset`` and read it back; return False when it failed."""


class RamStorage:
    """The log in memory: lost with the process (the virtual fish without a file)."""

    def __init__(self) -> None:
        """Start erased."""
        self.unit = bytearray(b'\xff' * ERASE_UNIT)
        self.fail = False   # a test's broken flash: every erase and program fails

    def read(self) -> bytes:
        """Return the unit."""
        return bytes(self.unit)

    def erase(self) -> bool:
        """Erase the unit (False when failing)."""
        if self.fail:
            return False
        self.unit[:] = b'\xff' * ERASE_UNIT
        return True

    def program(self, offset: int, data: bytes) -> bool:
        """Write and verify (False when failing)."""
        if self.fail:
            return False
        self.unit[offset:offset + len(data)] = data
        return self.unit[offset:offset + len(data)] == data


class FileStorage:
    """
    The log in a file of ERASE_UNIT bytes: a fish_sim started again on it keeps its calibration.

    An absent file is an erased unit; a short one is erased beyond its end. A write that
    fails (OSError, or the bytes read back differ) is a failed flash write.
    """

    def __init__(self, path: Path) -> None:
        """Use ``path`` (created at the first write)."""
        self.path = Path(path)

    def read(self) -> bytes:
        """Return the unit (0xFF beyond the file's end, or for an absent or unreadable file)."""
        try:
            data = self.path.read_bytes()[:ERASE_UNIT]
        except OSError:
            data = b''
        return data + b'\xff' * (ERASE_UNIT - len(data))

    def erase(self) -> bool:
        """Write an erased unit (False on an OSError)."""
        return self._write(0, b'\xff' * ERASE_UNIT, truncate=True)

    def program(self, offset: int, data: bytes) -> bool:
        """Write ``data`` at ``offset``, flush it to the disk, read it back."""
        return self._write(offset, data)

    def _write(self, offset: int, data: bytes, truncate: bool = False) -> bool:
        try:
            flags = os.O_RDWR | os.O_CREAT | (os.O_TRUNC if truncate else 0)
            fd = os.open(self.path, flags, 0o644)
            try:
                if os.fstat(fd).st_size < offset:   # a new file: erased up to the record
                    os.pwrite(fd, b'\xff' * (offset - os.fstat(fd).st_size),
                              os.fstat(fd).st_size)
                os.pwrite(fd, data, offset)
                os.fsync(fd)
                return os.pread(fd, len(data), offset) == data
            finally:
                os.close(fd)
        except OSError:
            return False


class Calibration:
    """
    Both servos' calibration in force, their sources, and the record log behind them.

    ``boot`` applies the winning record (each stored servo that fits, else the defaults);
    ``set_live``, ``save`` and ``factory`` are the SERVO_TRIM operations after the judging
    (``save``/``factory`` return False when the storage write failed: nothing changed).
    """

    def __init__(self, storage: Storage, limit_rad: float, frame_us: float,
                 default: ServoCal = DEFAULT) -> None:
        """Boot from ``storage``: servos judged against ``limit_rad`` and ``frame_us``."""
        self.storage = storage
        self.limit_rad = limit_rad
        self.frame_us = frame_us
        self.default = default
        self.cals = [default, default]
        self.sources = [CalibrationSource.DEFAULTS, CalibrationSource.DEFAULTS]
        record, _ = winning_record(storage.read())
        if record is not None:
            for i, stored in enumerate(record.servos):
                cal = self.with_values(stored.neutral_us, stored.us_per_rad, stored.direction)
                if stored.valid and self.fits(cal):
                    self.cals[i] = cal
                    self.sources[i] = CalibrationSource.STORED

    def with_values(self, neutral_us: float, us_per_rad: float, direction: int) -> ServoCal:
        """Return the build's calibration with these values (binary32)."""
        return replace(self.default, neutral_us=neutral_us, us_per_rad=us_per_rad,
                       direction=direction).binary32()

    def fits(self, cal: ServoCal) -> bool:
        """
        Return True when the board may run ``cal`` (app.c's ``trim_fits``).

        Direction +-1, us_per_rad > 0 (binary32) and ``fits`` with its limit and frame.
        """
        return (cal.direction in (1, -1) and math.isfinite(cal.neutral_us)
                and math.isfinite(cal.us_per_rad) and cal.us_per_rad > 0.0
                and fits(cal, self.limit_rad, self.frame_us))

    def set_live(self, servo: int, cal: ServoCal) -> None:
        """Use ``cal`` on ``servo`` (1 or 2) now, not saved."""
        self.cals[servo - 1] = cal
        self.sources[servo - 1] = CalibrationSource.LIVE

    def save(self, servo: int, cal: ServoCal) -> bool:
        """Write ``cal`` as ``servo``'s stored values and use it; False: the write failed."""
        stored = StoredServo(cal.neutral_us, cal.us_per_rad, cal.direction, True)
        if not self._write(servo, stored):
            return False
        self.cals[servo - 1] = cal
        self.sources[servo - 1] = CalibrationSource.STORED
        return True

    def factory(self, servo: int) -> bool:
        """Erase ``servo``'s stored values and use the defaults; False: the write failed."""
        if not self._write(servo, StoredServo()):
            return False
        self.cals[servo - 1] = self.default
        self.sources[servo - 1] = CalibrationSource.DEFAULTS
        return True

    def report(self, servo: int) -> ServoTrimReport:
        """Return the SERVO_TRIM_REPORT of ``servo`` now."""
        cal = self.cals[servo - 1]
        return ServoTrimReport(servo, self.sources[servo - 1], cal.direction, cal.neutral_us,
                               cal.us_per_rad, cal.min_us, cal.max_us)

    def _write(self, servo: int, part: StoredServo) -> bool:
        """Append a record with ``part`` for ``servo`` and the other servo's stored part."""
        unit = self.storage.read()
        record, end = winning_record(unit)
        servos = list(record.servos) if record is not None else [StoredServo(), StoredServo()]
        servos[servo - 1] = part
        generation = (record.generation + 1) if record is not None else 1
        data = Record(generation & 0xFFFFFFFF, (servos[0], servos[1])).encode()
        if end + RECORD_SIZE > len(unit):
            if not self.storage.erase():
                return False
            end = 0
        return self.storage.program(end, data)
