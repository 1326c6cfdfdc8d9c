# SPDX-License-Identifier: Apache-2.0
"""
Helpers of the in-the-loop tests: the board's debug console, a tap on the link, a ROS probe.

The emulator build of the firmware writes a debug console on USART2 (firmware/port/stm32f4/
debug_console.h): the board time of every 0x00 byte USART1 received ("Z"), every change of a
servo compare register with the value read back from the timer ("P"), the timer set-up and the
servo calibration ("C", "K"), each accepted GAIT's poll time ("G"), in gait mode polls more
than 1 ms apart ("J"), and the polls that took a HEARTBEAT or a SERVO_CMD ("T"). The ``Tap``
sits between bridge_node and the board's USART1 pty as a pseudo-terminal pair: it forwards
every byte both ways unchanged, frame by frame, and records what crossed. Since the board's "Z"
lines count the very 0x00 bytes the tap forwarded, the k-th delimiter the tap forwarded arrived
on the board at ``console.zeros[k]``: each frame the bridge sent has a board arrival time, on
the board's own clock.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import os
from pathlib import Path
import select
import threading
import time
import tty

from wirefish_bridge.codec import DecodedFrame, StreamDecoder
from wirefish_bridge.protocol import ServoCommand


def _open_raw(path: str) -> int:
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd)
    return fd


@dataclass(frozen=True)
class Calibration:
    """One servo's calibration as the board reports it."""

    neutral_us: float
    us_per_rad: float
    direction: int
    limit_rad: float


class Console:
    """Reads the debug console on a thread of its own and keeps what it says."""

    def __init__(self, path: str) -> None:
        self._fd = _open_raw(path)
        self.zeros: list[int] = []                      # board ms of each frame's end
        self.compares: list[tuple[int, int, int]] = []  # (board ms, channel, ticks)
        self.ticks_per_us: int | None = None
        self.lines_dropped = 0                          # "Z" lines the board had no room for
        self.rx_lost = 0                                # USART1 bytes lost to a full ring
        self.calibration: dict[int, Calibration] = {}
        self.gaits: list[tuple[int, int, int]] = []   # (board ms, gait_id, accepted count)
        # Board ms of each poll that took a HEARTBEAT (kind 0) or a SERVO_CMD (kind 1).
        self.taken: dict[int, list[int]] = {0: [], 1: []}
        self.jumps: list[tuple[int, int]] = []        # gait mode: (poll ms, next poll ms)
        self.malformed: list[str] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name='console', daemon=True)
        self._thread.start()

    def _run(self) -> None:
        pending = b''
        while not self._stop.is_set():
            if not select.select([self._fd], [], [], 0.05)[0]:
                continue
            try:
                chunk = os.read(self._fd, 65536)
            except OSError:
                time.sleep(0.01)
                continue
            *lines, pending = (pending + chunk).split(b'\n')
            for line in lines:
                self._parse(line.decode(errors='replace'))

    def _parse(self, line: str) -> None:
        fields = line.split()
        try:
            numbers = [int(f) for f in fields[1:]]
            if fields[0] == 'Z' and len(numbers) == 1:
                self.zeros.append(numbers[0])
            elif fields[0] == 'P' and len(numbers) == 3:
                self.compares.append((numbers[0], numbers[1], numbers[2]))
            elif fields[0] == 'C' and len(numbers) == 5:
                self.ticks_per_us = numbers[0]
                self.lines_dropped, self.rx_lost = numbers[2], numbers[3]
            elif fields[0] == 'G' and len(numbers) == 3:
                self.gaits.append((numbers[0], numbers[1], numbers[2]))
            elif fields[0] == 'T' and len(numbers) == 2 and numbers[0] in self.taken:
                self.taken[numbers[0]].append(numbers[1])
            elif fields[0] == 'J' and len(numbers) == 2:
                self.jumps.append((numbers[0], numbers[1]))
            elif fields[0] == 'K' and len(numbers) == 5:
                self.calibration[numbers[0]] = Calibration(
                    numbers[1] / 1000.0, numbers[2] / 1000.0, numbers[3], numbers[4] / 1e6)
            else:
                self.malformed.append(line)
        except (IndexError, ValueError):
            self.malformed.append(line)

    def ready(self) -> bool:
        """Return True once the board has reported its timer and both servos' calibration."""
        return self.ticks_per_us is not None and len(self.calibration) == 2

    def angle(self, channel: int, ticks: int) -> float:
        """Return the servo angle, in rad, that a compare value of ``channel`` stands for."""
        cal = self.calibration[channel]
        assert self.ticks_per_us is not None
        return (ticks / self.ticks_per_us - cal.neutral_us) / (cal.direction * cal.us_per_rad)

    def tick_rad(self, channel: int) -> float:
        """Return the angle of one timer tick of ``channel`` (rad)."""
        assert self.ticks_per_us is not None
        return 1.0 / (self.ticks_per_us * self.calibration[channel].us_per_rad)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        os.close(self._fd)


@dataclass(frozen=True)
class Crossing:
    """A frame the tap saw: host monotonic time, and for host frames the delimiter index."""

    time: float
    frame: DecodedFrame
    zero_index: int = -1   # host -> board: index of its closing 0x00 among frame ends forwarded
    dropped: bool = False


@dataclass
class TapRecord:
    """What crossed the tap, each way."""

    to_board: list[Crossing] = field(default_factory=list)
    to_host: list[Crossing] = field(default_factory=list)


class Tap:
    """
    A pty pair in front of the board's USART1 pty: the bridge opens ``link``.

    Host bytes are forwarded at each 0x00, whole runs at a time, so ``inject`` and
    ``drop_servo_cmd`` act at frame boundaries; board bytes are forwarded as they come (and
    dropped while no host reads them). A writer thread of its own writes to the board, so the
    reader never waits on it: QEMU, blocked writing a byte nobody reads, would never take
    the bytes the reader waits to write.
    """

    def __init__(self, link: Path, board_pty: str) -> None:
        self.master, self._slave = os.openpty()
        tty.setraw(self._slave)
        os.set_blocking(self.master, False)
        self.link = link
        os.symlink(os.ttyname(self._slave), link)
        self._board = _open_raw(board_pty)
        self.record = TapRecord()
        self.host_decoder = StreamDecoder()    # every byte the bridge wrote, as written
        self.board_decoder = StreamDecoder()   # every byte the board wrote, from a frame start
        self._board_joined = False
        self.zeros_forwarded = 0   # 0x00 bytes forwarded that end a frame (follow a non-zero)
        self._last_forwarded = 0
        self.drop_servo_cmd = False
        self._host_pending = b''
        self._lock = threading.Lock()
        self._to_board: deque[bytes] = deque()
        self._queued = threading.Condition(self._lock)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name='tap', daemon=True)
        self._writer = threading.Thread(target=self._write_board, name='tap-writer',
                                        daemon=True)
        self._thread.start()
        self._writer.start()

    def _write_board(self) -> None:
        while not self._stop.is_set():
            with self._queued:
                while not self._to_board and not self._stop.is_set():
                    self._queued.wait(0.1)
                data = b''.join(self._to_board)
                self._to_board.clear()
            if data:
                _write_all(self._board, data, self._stop)

    def _forward(self, data: bytes) -> None:
        """Queue ``data`` for the board (hold the lock)."""
        self._to_board.append(data)
        for byte in data:
            if byte == 0 and self._last_forwarded != 0:
                self.zeros_forwarded += 1
            self._last_forwarded = byte
        self._queued.notify()

    def _run(self) -> None:
        while not self._stop.is_set():
            ready = select.select([self.master, self._board], [], [], 0.05)[0]
            if self.master in ready:
                self._from_host()
            if self._board in ready:
                self._from_board()

    def _from_host(self) -> None:
        try:
            chunk = os.read(self.master, 65536)
        except OSError:
            return
        now = time.monotonic()
        self.host_decoder.feed(chunk)
        *runs, self._host_pending = (self._host_pending + chunk).split(b'\x00')
        for run in runs:
            frames = StreamDecoder().feed(b'\x00' + run + b'\x00') if run else []
            frame = frames[0] if frames else None
            drop = (frame is not None and isinstance(frame.message, ServoCommand)
                    and self.drop_servo_cmd)
            with self._lock:
                if not drop:
                    self._forward(run + b'\x00')
                if frame is not None:   # a decoded frame is a non-empty run: it ends a frame
                    self.record.to_board.append(
                        Crossing(now, frame, -1 if drop else self.zeros_forwarded - 1, drop))

    def _from_board(self) -> None:
        try:
            chunk = os.read(self._board, 65536)
        except OSError:
            return
        now = time.monotonic()
        decoded = chunk
        if not self._board_joined:
            # The board may be mid-frame when the tap opens its pty (QEMU boots on its own
            # time): decode from the first 0x00, which every frame has before and after it.
            start = chunk.find(b'\x00')
            decoded, self._board_joined = (chunk[start:], True) if start >= 0 else (b'', False)
        for frame in self.board_decoder.feed(decoded):
            self.record.to_host.append(Crossing(now, frame))
        try:
            os.write(self.master, chunk)
        except OSError:
            pass   # the pty's buffer is full: nobody reads the host side (the bridge is dead)

    def inject(self, data: bytes) -> int:
        """Write ``data`` to the board between two frames; return its last frame end's index."""
        with self._lock:
            self._forward(data)
            return self.zeros_forwarded - 1

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        self._writer.join(2.0)
        for fd in (self.master, self._slave, self._board):
            os.close(fd)
        if self.link.is_symlink():
            self.link.unlink()


def _write_all(fd: int, data: bytes, stop: threading.Event | None = None) -> None:
    view = memoryview(data)
    while view and not (stop is not None and stop.is_set()):
        try:
            written = os.write(fd, view)
        except BlockingIOError:
            select.select([], [fd], [], 0.1)
            continue
        view = view[written:]


def board_time_of(console: Console, crossing: Crossing) -> int:
    """Return the board time (ms) at which a forwarded host frame's closing 0x00 arrived."""
    return console.zeros[crossing.zero_index]
