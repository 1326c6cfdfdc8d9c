# SPDX-License-Identifier: Apache-2.0
"""
The servo calibration from the shore on the host board: SERVO_TRIM and its storage.

wirefish-fw-host started on an absent ``--calibration-file`` boots on the build's values
(both boot reports DEFAULTS); a SAVE there is acknowledged, reported STORED and written to the
file as PROTOCOL.md's record (magic, generation 1, the values, zlib's CRC-32); the program
started again on that file boots on it. Through the library: a SET is live and gone after a
power cycle, a SAVE survives it, and a failed write changes nothing. The frames are encoded
and decoded by the C codec (flat records of wf_host.h).
"""

import os
import select
import struct
import subprocess
import time
import zlib

from firmware_host import BUILD, FirmwareHost, MSG_DTYPE
import numpy as np
import pytest
from ros_utils import stop_process

PROGRAM = BUILD / 'host' / 'wirefish-fw-host'
SERVO_TRIM, SERVO_TRIM_REPORT, ACK, HEARTBEAT, HEALTH = 0x12, 0x22, 0x03, 0x01, 0x30
READ, SET, SAVE = 0, 1, 2
DEFAULTS, STORED, LIVE = 0, 1, 2
STORAGE_FAILED = 8
FAIL_PROGRAM = 2  # wf_host_storage_fault_t


def record(kind: int, seq: int, ints: tuple[int, ...], floats: tuple[float, ...] = ()):
    """Return one flat message (MSG_DTYPE)."""
    r = np.zeros(1, MSG_DTYPE)
    r['type'], r['seq'] = kind, seq
    r['n'][0, :len(ints)] = ints
    r['f'][0, :len(floats)] = floats
    return r


def hello(seq: int = 0) -> np.ndarray:
    """Return the host's HEARTBEAT, version 2."""
    r = record(HEARTBEAT, seq, ())
    r['code'], r['role'] = 2, 0
    return r


def trim(seq: int, servo: int, op: int, direction: int = 0, neutral_us: float = 0.0,
         us_per_rad: float = 0.0) -> np.ndarray:
    """Return a SERVO_TRIM."""
    return record(SERVO_TRIM, seq, (servo, op, direction, 0), (neutral_us, us_per_rad))


def reports(frames: np.ndarray) -> list[tuple[int, int, int, float, float]]:
    """Return the SERVO_TRIM_REPORTs: (servo, source, direction, neutral_us, us_per_rad)."""
    return [(int(f['n'][0]), int(f['n'][1]), int(f['n'][2]), float(f['f'][0]),
             float(f['f'][1])) for f in frames if f['type'] == SERVO_TRIM_REPORT]


class Board:
    """
    wirefish-fw-host on a pty with a calibration file; the C codec for its frames.

    The pty is opened as a plain file, not with pyserial: pyserial's open flushes the input
    queue (TCIFLUSH), and the boot reports the board writes at once after saying its pty were
    flushed with it whenever this process opened the pty later than that (seen in a loaded
    full run). The program keeps the pty raw and its other end open, so nothing is lost here.
    """

    def __init__(self, lib: FirmwareHost, path) -> None:
        """Start the program on ``path``; wait for its pty."""
        self.lib = lib
        self.proc = subprocess.Popen([str(PROGRAM), '--pty', '--calibration-file', str(path)],
                                     stdout=subprocess.PIPE, text=True, start_new_session=True)
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        assert line.startswith('pty: '), line
        self.fd = os.open(line.split(' ', 1)[1].strip(), os.O_RDWR | os.O_NOCTTY)
        self.received = b''

    def send(self, *messages: np.ndarray) -> None:
        """Write the messages, encoded in C."""
        os.write(self.fd, self.lib.encode_stream(np.concatenate(messages)))

    def until(self, done, timeout_s: float = 5.0) -> np.ndarray:
        """Read until ``done(frames)`` holds for every frame received so far; return them."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if select.select([self.fd], [], [], 0.05)[0]:
                self.received += os.read(self.fd, 4096)
            frames, _ = self.lib.decode_stream(self.received)
            if done(frames):
                return frames
        raise AssertionError(f'not seen within {timeout_s} s')

    def stop(self) -> None:
        """Close the pty and SIGINT the program; it exits 0."""
        os.close(self.fd)
        assert stop_process(self.proc) == 0


def test_a_saved_calibration_outlives_the_host_program(host_lib: FirmwareHost, tmp_path):
    path = tmp_path / 'calibration.bin'
    board = Board(host_lib, path)
    try:
        boot = reports(board.until(lambda fs: len(reports(fs)) >= 2))
        assert [(servo, source) for servo, source, *_ in boot] == [(1, DEFAULTS), (2, DEFAULTS)]
        assert not path.exists()  # absent: an erased unit, nothing written until a save
        board.send(hello(), trim(1, 2, SAVE, -1, 1480.0, 600.0))
        frames = board.until(lambda fs: any(f['type'] == ACK and f['n'][1] == 1 for f in fs)
                             and len(reports(fs)) >= 3)
        ack = next(f for f in frames if f['type'] == ACK and f['n'][1] == 1)
        assert (ack['n'][0], ack['n'][2]) == (SERVO_TRIM, 0)
        assert reports(frames)[2] == (2, STORED, -1, 1480.0, 600.0)
    finally:
        board.stop()
    data = path.read_bytes()
    assert len(data) == 16384 and data[36:] == b'\xff' * (16384 - 36)
    magic, generation = struct.unpack_from('<II', data)
    servo_2 = struct.unpack_from('<ffbB2x', data, 20)
    assert (magic, generation, data[:4]) == (0x4C434657, 1, b'WFCL')
    assert servo_2 == (1480.0, 600.0, -1, 1) and data[8:20] == bytes(12)
    assert struct.unpack_from('<I', data, 32)[0] == zlib.crc32(data[:32])
    board = Board(host_lib, path)
    try:
        boot = reports(board.until(lambda fs: len(reports(fs)) >= 2))
        assert boot == [(1, DEFAULTS, 1, 1500.0, pytest.approx(636.619772)),
                        (2, STORED, -1, 1480.0, 600.0)]
    finally:
        board.stop()


def _trim_on(board: FirmwareHost, t: int, message: np.ndarray) -> np.ndarray:
    out = board.step(t, board.encode_stream(message))
    frames, _ = board.decode_stream(out + board.step(t + 1))
    return frames


def test_set_is_forgotten_and_save_kept_across_a_power_cycle(board: FirmwareHost):
    board.step(0, board.encode_stream(hello()))
    _trim_on(board, 10, trim(1, 1, SET, 1, 1520.0, 600.0))
    assert (board.calibration()[0].source, board.compare(0)) == (LIVE, 1520)
    board.reset(keep_storage=True)
    assert (board.calibration()[0].source, board.compare(0)) == (DEFAULTS, 1500)
    board.step(0, board.encode_stream(hello()))
    _trim_on(board, 10, trim(1, 1, SAVE, 1, 1520.0, 600.0))
    board.reset(keep_storage=True)
    assert (board.calibration()[0].source, board.compare(0)) == (STORED, 1520)
    board.reset()  # the fixture's reset: an erased storage
    assert board.calibration()[0].source == DEFAULTS


def test_a_failed_write_is_acked_8_and_changes_nothing(board: FirmwareHost):
    board.step(0, board.encode_stream(hello()))
    board.step(1)  # the boot's second SERVO_TRIM_REPORT (servo 2) out
    before = bytes(board.calibration()[0]), board.storage(0, 64)
    board.set_storage_fault(FAIL_PROGRAM)
    try:
        frames = _trim_on(board, 10, trim(1, 1, SAVE, 1, 1520.0, 600.0))
    finally:
        board.set_storage_fault(0)
    acks = [f for f in frames if f['type'] == ACK]
    assert [(int(a['n'][0]), int(a['n'][2])) for a in acks] == [(SERVO_TRIM, STORAGE_FAILED)]
    assert reports(frames) == []
    assert (bytes(board.calibration()[0]), board.storage(0, 64)) == before
