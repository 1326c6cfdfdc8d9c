# SPDX-License-Identifier: Apache-2.0
"""
The firmware failing on purpose on the emulated board (QEMU), and what it reports after.

The emulator image's debug console takes one-letter commands (firmware/port/stm32f4/
debug_console.h): "H" a HardFault, "W" a hung poll loop, "S" a stack overflow. The fault path
writes an "F" line (cause, PC, both compare registers read back after it set them neutral)
just before its reset; the rebooted board's "R" lines and its HEALTH messages on the link say
why it reset. QEMU 7.2 models no IWDG: the image's stand-in (SysTick interrupts since the last
feed) takes the same path with the cause IWDG; RCC_CSR is not modelled either, so the emulated
board's cause is the record's alone (UNKNOWN at its first boot). Those parts are tested on the
host port (test/firmware/test_fw_fail_safe.py). A servo calibration saved over the link
(SERVO_TRIM SAVE) outlives the fault's reset in the QEMU build's .noinit unit (QEMU's flash is
ROM), and the fault path drives its saved neutral.

bridge_node, on the board's link, shows the fault and its PC in /diagnostics (its
fish_reset_cause and fish_fault_pc). The last test shows with nm that the hardware image holds
none of the console.
"""

from collections.abc import Iterator
from dataclasses import dataclass
import os
from pathlib import Path
import select
import subprocess
import threading
import time
import tty

from firmware_host import build_firmware, FIRMWARE
import pytest
from wirefish_bridge.codec import FrameEncoder, StreamDecoder
from wirefish_bridge.protocol import (Health, HealthFlags, Heartbeat, PROTOCOL_VERSION,
                                      ResetCause, Role, ServoCommand, Telemetry)
from wirefish_launcher.qemu_board import QemuBoard

# Not a module that loads the machine (machine_share.py): QEMU takes ~20 % of a core, and the
# watchdog's stand-in counts SysTick interrupts, which a descheduled QEMU drops with the main
# loop's polls (failsafe.c), so a busy host fires no fault. It passed twice sharing one core
# with a busy loop (`taskset -c 1` both).

NEUTRAL_TICKS = 1500
COMMANDED = (0.5, -0.5)
COMMANDED_TICKS = (1818, 1182)   # 1500 +- 636.62 x 0.5 us
CFSR_UNDEFINSTR = 1 << 16
CFSR_MSTKERR, CFSR_DACCVIOL, CFSR_STKERR = 1 << 4, 1 << 1, 1 << 12
HFSR_FORCED = 1 << 30
STACK_GUARD = 32
STACK_BYTES = 2048
BOOT_MS = 500


@dataclass(frozen=True)
class Report:
    """An "R" line: what wf_hal_health_port reports."""

    cause: int
    pc: int
    lr: int
    cfsr: int
    hfsr: int
    flags: int
    stack_free: int
    stack_size: int
    clock: int


class Board:
    """The board's console (read, and commands written) and its link (read, frames written)."""

    def __init__(self, qemu: QemuBoard, link: bool = True) -> None:
        assert qemu.ports is not None and qemu.ports.console is not None
        self.console = _open_raw(qemu.ports.console)
        self.link = _open_raw(qemu.ports.link) if link else -1
        self.lines: list[str] = []
        self.frames: list = []
        self._decoder = StreamDecoder()
        self._encoder = FrameEncoder()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        pending = b''
        while not self._stop.is_set():
            ready = select.select([fd for fd in (self.console, self.link) if fd >= 0], [], [],
                                  0.05)[0]
            for fd in ready:
                try:
                    chunk = os.read(fd, 65536)
                except OSError:
                    continue
                with self._lock:
                    if fd == self.link:
                        self.frames += [f.message for f in self._decoder.feed(chunk)]
                    else:
                        *lines, pending = (pending + chunk).split(b'\n')
                        self.lines += [line.decode(errors='replace') for line in lines]

    def command(self, letter: str) -> None:
        os.write(self.console, letter.encode())

    def send(self, *messages) -> None:
        os.write(self.link, b''.join(self._encoder.encode(m) for m in messages))

    def wait(self, predicate, timeout_s: float = 30.0):
        """Return predicate()'s first true value within ``timeout_s``; fail otherwise."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self._lock:
                value = predicate()
            if value:
                return value
            time.sleep(0.05)
        with self._lock:
            raise AssertionError(f'not seen within {timeout_s:g} s; console: {self.lines[-8:]}')

    def tagged(self, tag: str, since: int = 0) -> list[list[int]]:
        return [[int(v) for v in line.split()[1:]] for line in self.lines[since:]
                if line.startswith(tag + ' ')]

    def reports(self, since: int = 0) -> list[Report]:
        return [Report(*values) for values in self.tagged('R', since) if len(values) == 9]

    def healths(self, since: int = 0) -> list[Health]:
        return [m for m in self.frames[since:] if isinstance(m, Health)]

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        os.close(self.console)
        if self.link >= 0:
            os.close(self.link)


def _open_raw(path: str) -> int:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    return fd


@pytest.fixture
def emulated(board: QemuBoard) -> Iterator[Board]:
    """Yield the running board's console and link once it reported its health once."""
    reader = Board(board)
    reader.wait(lambda: reader.reports())
    yield reader
    reader.close()


def _fail(board: Board, letter: str) -> tuple[list[int], Report, Health]:
    """Send ``letter``; return the fault line, the next boot's report and HEALTH."""
    lines, frames = len(board.lines), len(board.frames)
    board.command(letter)
    fault = board.wait(lambda: board.tagged('F', lines))[0]
    after = board.lines.index(next(line for line in board.lines[lines:]
                                   if line.startswith('F '))) + 1
    report = board.wait(lambda: board.reports(after))[0]
    # The HEALTH the board sends right after its boot (the link's pty stayed open across the
    # reset: nothing was lost), not a periodic one that left before the fault.
    health = board.wait(lambda: [h for h in board.healths(frames) if h.uptime_ms < BOOT_MS])[0]
    return fault, report, health


def _function_at(pc: int, image: Path) -> str:
    result = subprocess.run(['arm-none-eabi-addr2line', '-f', '-i', '-e', str(image), hex(pc)],
                            capture_output=True, text=True, check=True)
    return result.stdout


def test_first_boot_reports_no_cause_qemu_has_no_reset_flags(emulated: Board):
    report = emulated.reports()[0]
    assert report.cause == ResetCause.UNKNOWN and not report.flags & HealthFlags.FAULT_RECORD
    assert report.flags & HealthFlags.STACK_GUARD
    assert report.stack_size == STACK_BYTES - STACK_GUARD and 0 < report.stack_free
    health = emulated.wait(lambda: emulated.healths())[-1]
    assert health.reset_cause == ResetCause.UNKNOWN and health.stack_size == report.stack_size


def test_a_hardfault_sets_both_servos_neutral_resets_and_is_reported_with_its_pc(
        emulated: Board, qemu_image: Path):
    emulated.send(Heartbeat(PROTOCOL_VERSION, Role.HOST, 0), ServoCommand(*COMMANDED))
    emulated.wait(lambda: {(ch, ticks) for _, ch, ticks in emulated.tagged('P')} >= {
        (0, COMMANDED_TICKS[0]), (1, COMMANDED_TICKS[1])})
    emulated.send(ServoCommand(*COMMANDED))   # within the command timeout: still commanded
    fault, report, health = _fail(emulated, 'H')
    cause, pc, ticks_0, ticks_1 = fault
    assert cause == ResetCause.FAULT and (ticks_0, ticks_1) == (NEUTRAL_TICKS, NEUTRAL_TICKS)
    assert 'debug_console_poll' in _function_at(pc, qemu_image)   # the "H" command's udf
    assert (report.cause, report.pc) == (ResetCause.FAULT, pc)
    assert report.cfsr & CFSR_UNDEFINSTR and report.hfsr & HFSR_FORCED
    assert report.flags & HealthFlags.FAULT_RECORD
    assert (health.reset_cause, health.fault_pc, health.fault_cfsr, health.fault_hfsr) == (
        ResetCause.FAULT, pc, report.cfsr, report.hfsr)
    assert health.flags & HealthFlags.FAULT_RECORD


def test_a_hung_poll_loop_is_reset_by_the_watchdog_and_reported(emulated: Board):
    fault, report, health = _fail(emulated, 'W')
    assert fault[0] == ResetCause.IWDG and fault[2:] == [NEUTRAL_TICKS, NEUTRAL_TICKS]
    assert report.cause == ResetCause.IWDG and not report.flags & HealthFlags.FAULT_RECORD
    assert health.reset_cause == ResetCause.IWDG


def test_a_stack_overflow_faults_resets_and_the_board_runs_on_unharmed(emulated: Board):
    calibration = emulated.tagged('K')[:2]
    fault, report, health = _fail(emulated, 'S')
    # The guard was hit (MemManage, data access) and the fault's own stacking below RAM faulted
    # too: no frame to read a PC from, and nothing written below the stack.
    assert fault[0] == ResetCause.FAULT and fault[1] == 0
    assert report.cause == ResetCause.FAULT and report.cfsr & (CFSR_DACCVIOL | CFSR_MSTKERR)
    assert report.cfsr & CFSR_STKERR
    assert health.reset_cause == ResetCause.FAULT and health.fault_cfsr == report.cfsr
    lines = len(emulated.lines)
    assert emulated.wait(lambda: emulated.tagged('K', lines)[:2]) == calibration
    frames = len(emulated.frames)
    telemetry = emulated.wait(lambda: [m for m in emulated.frames[frames:]
                                       if isinstance(m, Telemetry)])
    assert (telemetry[-1].servo_1, telemetry[-1].servo_2) == (0.0, 0.0)


# PROTOCOL.md's SERVO_TRIM example: SAVE servo 1, direction -1, 1520 us at 0 rad, 600 us/rad.
SAVE_SERVO_1 = bytes.fromhex('00 03 12 0d 04 01 02 ff 01 01 03 be 44 01 05 16 44 09 ac 00')


def test_a_saved_calibration_outlives_a_fault_reset_in_the_noinit_unit(emulated: Board):
    # QEMU's flash is ROM: the QEMU build's unit is .noinit RAM, which the reset keeps.
    lines = len(emulated.lines)
    emulated.send(Heartbeat(PROTOCOL_VERSION, Role.HOST, 0))
    os.write(emulated.link, SAVE_SERVO_1)
    saved = [0, 1520000, 600000, -1]
    assert emulated.wait(lambda: [k for k in emulated.tagged('K', lines) if k[:4] == saved])
    assert emulated.wait(lambda: (0, 1520) in {(ch, t) for _, ch, t in emulated.tagged('P')})
    fault, _, _ = _fail(emulated, 'H')
    assert fault[2:] == [1520, NEUTRAL_TICKS]   # the fault path's neutral is the saved one
    after = len(emulated.lines)
    calibration = emulated.wait(lambda: emulated.tagged('K', after)[:2])
    assert [k[:4] for k in calibration] == [saved, [1, 1500000, 636620, 1]]


def _diagnosed(probe, key: str, value: str) -> dict[str, str] | None:
    """Return the newest /diagnostics status whose ``key`` is ``value``, if any."""
    for array in reversed(probe.diagnostics):
        for status in array.status:
            values = {kv.key: kv.value for kv in status.values}
            if values.get(key) == value:
                return values
    return None


@pytest.mark.ros
@pytest.mark.parametrize('letter, cause', [('H', 'FAULT'), ('W', 'IWDG')])
def test_the_bridge_shows_why_the_board_reset_in_diagnostics(board: QemuBoard, start_bridge,
                                                             probe, letter: str, cause: str):
    console = Board(board, link=False)
    try:
        console.wait(lambda: console.reports())
        start_bridge(board.link)
        assert probe.spin_until(lambda: _diagnosed(probe, 'link_state', 'connected'), 30.0)
        lines = len(console.lines)
        console.command(letter)
        pc = console.wait(lambda: console.tagged('F', lines))[0][1]
        # A fault names its PC; the watchdog's reset has no fault record.
        assert probe.spin_until(lambda: (_diagnosed(probe, 'fish_reset_cause', cause) or {}).get(
            'fish_fault_pc') == (f'0x{pc:08x}' if cause == 'FAULT' else None), 30.0), \
            probe.diagnostics[-1:]
    finally:
        console.close()


def test_the_hardware_image_holds_no_test_console(qemu_image: Path):
    build_firmware('arm')

    def symbols(image: Path) -> set[str]:
        out = subprocess.run(['arm-none-eabi-nm', str(image)], capture_output=True, text=True,
                             check=True).stdout
        return {line.split()[-1] for line in out.splitlines()}

    hardware = symbols(FIRMWARE / 'build' / 'arm' / 'wirefish.elf')
    emulator = symbols(qemu_image)
    hooks = {'debug_console_init', 'debug_console_poll', 'trace_rx_byte', 'trace_compare',
             'trace_fault', 'board_watchdog_tick'}
    assert hooks <= emulator
    assert not {name for name in hardware if name in hooks or name.startswith('debug_')}
    assert {'wf_fault_handler', 'board_fail', 'board_watchdog_feed'} <= hardware
