# SPDX-License-Identifier: Apache-2.0
"""
Serial transport of the bridge: pyserial, a reader thread, reconnection with backoff.

No rclpy and no protocol knowledge: bytes in (``on_data`` called from the reader thread),
bytes out (``write``, non-blocking). When the device disappears (unplugged, or the virtual
fish closed its pseudo-terminal) the reader thread reports it through ``on_state``, closes the
port, and retries opening the same path with exponential backoff until it is back; nobody has
to restart anything. Errors are typed (``LinkError`` and subclasses); nothing calls sys.exit.

The port is opened exclusively: an advisory ``flock`` (pyserial's ``exclusive=True``), so a
second link on the same device (another bridge, even as root) fails to open, says who holds it
and keeps retrying, instead of splitting the byte stream. (TIOCEXCL is not used: root ignores
it, and a process killed while holding it leaves the flag on a pty whose other end stays open,
locking out everyone else; a flock dies with its holder.)

With ``identify_timeout_s`` the link writes nothing until the peer has identified itself: the
consumer, which understands the bytes, calls ``identify_peer()`` from ``on_data`` (the reader
thread, so the identification belongs to the same open of the device). Until then the state
is IDENTIFYING and ``write`` raises ``PeerNotIdentified``; a peer that does not identify
itself within the timeout is closed and the path is reopened with backoff (it may point at
another device by then, e.g. a virtual fish's symlink re-pointed).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
import enum
import errno
import os
import threading
import time

import serial


class LinkError(Exception):
    """Base class of the transport's errors."""


class LinkDown(LinkError):
    """The port is not open (device absent, or reconnecting)."""


class LinkWriteError(LinkError):
    """A write failed or was cut short (device gone, or its buffer full)."""


class LinkRefused(LinkError):
    """The port was not opened: the check before opening (``open_check``) refused it."""


class PeerNotIdentified(LinkError):
    """The port is open but the device has not identified itself yet: nothing is written."""


class LinkState(enum.StrEnum):
    """State of the link, as reported to ``on_state`` (and /diagnostics' ``link_state``)."""

    CONNECTING = 'connecting'
    IDENTIFYING = 'identifying'   # open, waiting for the peer to identify itself
    CONNECTED = 'connected'
    DISCONNECTED = 'disconnected'
    STOPPED = 'stopped'


@dataclass
class LinkStats:
    """Counters of a ``SerialLink`` (monotonic). ``reconnects`` = successful opens - 1."""

    opens: int = 0
    reconnects: int = 0
    disconnects: int = 0
    open_failures: int = 0
    bytes_in: int = 0
    bytes_out: int = 0
    write_failures: int = 0
    writes_withheld: int = 0   # writes refused because the peer had not identified itself
    identify_timeouts: int = 0  # opens closed again: the peer never identified itself
    last_open_unidentified: bool = False  # the last open ended so (until the next event)
    last_error: str = ''
    callback_errors: int = 0  # exceptions raised by on_data (the reader goes on)


def next_backoff(current_s: float, minimum_s: float, maximum_s: float) -> float:
    """Return the next retry delay: double ``current_s``, within [minimum_s, maximum_s]."""
    return min(maximum_s, max(minimum_s, 2.0 * current_s))


class SerialLink:
    """
    One serial port, kept open by a reader thread.

    ``on_data(chunk)`` and ``on_state(state, detail)`` run on the reader thread: keep them
    short (the bridge feeds its decoder and wakes its executor). ``write`` may be called from
    any thread and never blocks.
    """

    def __init__(self, port: str, baudrate: int, on_data: Callable[[bytes], None],
                 on_state: Callable[[LinkState, str], None] | None = None, *,
                 backoff_min_s: float = 0.1, backoff_max_s: float = 1.0,
                 read_timeout_s: float = 0.05, identify_timeout_s: float | None = None,
                 open_check: Callable[[str], str | None] = lambda port: None,
                 serial_factory: Callable[..., serial.Serial] = serial.Serial) -> None:
        """
        Configure the link; nothing is opened before ``start``.

        ``identify_timeout_s`` None: writes go out as soon as the port is open (no
        identification). ``open_check(port)`` runs before every open and returns why the port
        must not be opened now (the link retries later), or None.
        """
        self.port = port
        self.baudrate = baudrate
        self.stats = LinkStats()
        self._on_data = on_data
        self._on_state = on_state or (lambda state, detail: None)
        self._backoff_min_s = backoff_min_s
        self._backoff_max_s = backoff_max_s
        self._read_timeout_s = read_timeout_s
        self._identify_timeout_s = identify_timeout_s
        self._open_check = open_check
        self._factory = serial_factory
        self._serial: serial.Serial | None = None
        self._identified = False   # the peer of the current open identified itself
        self._opened_at = 0.0
        self._lock = threading.Lock()   # guards _serial between the reader and writers
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.state = LinkState.STOPPED

    @property
    def connected(self) -> bool:
        """Return True while the port is open (and its peer identified, if that is required)."""
        return self.state is LinkState.CONNECTED

    def identify_peer(self) -> None:
        """Accept the peer of the current open: writes go out from now (call from on_data)."""
        with self._lock:
            if self._serial is None or self._identified:
                return
            self._identified = True
        self.stats.last_open_unidentified = False
        self._set_state(LinkState.CONNECTED, f'{self.port}: peer identified')

    def start(self) -> None:
        """Start the reader thread (which opens the port); idempotent."""
        if self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name=f'serial:{self.port}',
                                        daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop the reader thread, join it and close the port."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout_s)
            self._thread = None
        self._close()
        self._set_state(LinkState.STOPPED, 'stopped')

    def write(self, data: bytes) -> None:
        """
        Write ``data`` without blocking.

        Raises ``LinkDown`` when the port is not open, ``PeerNotIdentified`` before its peer
        identified itself, ``LinkWriteError`` when the device failed or took only part of
        ``data`` (the receiver discards the cut frame).
        """
        with self._lock:
            port = self._serial
            if port is None:
                raise LinkDown(f'{self.port} is not open')
            if not self._identified:
                self.stats.writes_withheld += 1
                raise PeerNotIdentified(f'{self.port} has not identified itself')
            try:
                written = _write_without_blocking(port, data)
            except (serial.SerialException, OSError) as error:
                self.stats.write_failures += 1
                raise LinkWriteError(f'write to {self.port} failed: {error}') from error
        self.stats.bytes_out += written or 0
        if written != len(data):
            self.stats.write_failures += 1
            raise LinkWriteError(f'{self.port} took {written} of {len(data)} bytes')

    def _set_state(self, state: LinkState, detail: str) -> None:
        if state is not self.state:
            self.state = state
            self._on_state(state, detail)

    def _close(self) -> None:
        with self._lock:
            port, self._serial = self._serial, None
            self._identified = False
        if port is not None:
            try:
                port.close()
            except (serial.SerialException, OSError):
                pass  # closing a vanished device may fail; it is closed either way

    def _open(self) -> bool:
        try:
            refusal = self._open_check(self.port)
            if refusal is not None:
                raise LinkRefused(refusal)
            # write_timeout=0: non-blocking writes, so no caller ever waits on the device.
            # exclusive=True: flock(LOCK_EX | LOCK_NB) before any termios change.
            port = self._factory(self.port, self.baudrate, timeout=self._read_timeout_s,
                                 write_timeout=0, exclusive=True)
            port.reset_input_buffer()  # stale bytes from before we were listening
        except (LinkRefused, serial.SerialException, OSError, ValueError) as error:
            self.stats.open_failures += 1
            self.stats.last_open_unidentified = False   # this failure is the news now
            reason = _open_failure(self.port, error)
            if reason != self.stats.last_error:  # say it once, not at every retry
                self._on_state(self.state, f'cannot open {self.port}: {reason}; retrying')
            self.stats.last_error = reason
            return False
        with self._lock:
            self._serial = port
            self._identified = self._identify_timeout_s is None
        self._opened_at = time.monotonic()
        self.stats.opens += 1
        if self.stats.opens > 1:
            self.stats.reconnects += 1
        return True

    def _run(self) -> None:
        backoff = self._backoff_min_s
        self._set_state(LinkState.CONNECTING, f'opening {self.port}')
        while not self._stop.is_set():
            port = self._serial
            if port is None:
                if self._open():
                    backoff = self._backoff_min_s
                    if self._identified:
                        self._set_state(LinkState.CONNECTED, f'{self.port} open')
                    else:
                        self._set_state(LinkState.IDENTIFYING,
                                        f'{self.port} open, waiting for it to identify itself')
                else:
                    self._stop.wait(backoff)
                    backoff = next_backoff(backoff, self._backoff_min_s, self._backoff_max_s)
                continue
            if self._identify_overdue():
                self.stats.identify_timeouts += 1
                self.stats.last_open_unidentified = True
                self.stats.last_error = (f'{self.port} did not identify itself within '
                                         f'{self._identify_timeout_s:g} s')
                self._close()
                self._set_state(LinkState.CONNECTING,
                                f'{self.stats.last_error}; closed, retrying')
                self._stop.wait(backoff)
                backoff = next_backoff(backoff, self._backoff_min_s, self._backoff_max_s)
                continue
            try:
                chunk = port.read(port.in_waiting or 1)
            except (serial.SerialException, OSError, TypeError, AttributeError) as error:
                # TypeError/AttributeError: pyserial's read on a port closed under it.
                self.stats.disconnects += 1
                self.stats.last_open_unidentified = False
                self.stats.last_error = str(error)
                self._close()
                self._set_state(LinkState.DISCONNECTED, f'{self.port} lost: {error}')
                self._stop.wait(backoff)
                continue
            if chunk:
                self.stats.bytes_in += len(chunk)
                try:
                    self._on_data(chunk)
                except Exception as error:  # noqa: B902 (a consumer's bug must not end reading)
                    self.stats.callback_errors += 1
                    self.stats.last_error = f'on_data failed: {error!r}'
        self._close()

    def _identify_overdue(self) -> bool:
        return (not self._identified and self._identify_timeout_s is not None
                and time.monotonic() - self._opened_at > self._identify_timeout_s)


def _open_failure(path: str, error: Exception) -> str:
    """Return why opening ``path`` failed; a lock held by another process is named as such."""
    if isinstance(error, LinkRefused):
        return str(error)
    if getattr(error, 'errno', None) in (errno.EAGAIN, errno.EWOULDBLOCK):
        holder = lock_holder(path)
        return (f'in use by another process{f" (pid {holder})" if holder else ""}: it holds '
                'the exclusive lock')
    return str(error)


def lock_holder(path: str, locks: str = '/proc/locks') -> int | None:
    """Return the pid holding a flock on the device behind ``path`` (Linux), or None."""
    try:
        info = os.stat(path)
        with open(locks, encoding='ascii') as table:
            lines = table.read().splitlines()
    except OSError:
        return None
    inode = f'{os.major(info.st_dev):02x}:{os.minor(info.st_dev):02x}:{info.st_ino}'
    for line in lines:
        fields = line.split()   # '1: FLOCK ADVISORY WRITE <pid> <maj:min:inode> 0 EOF'
        if len(fields) >= 6 and fields[1] == 'FLOCK' and fields[5] == inode:
            return int(fields[4]) if fields[4].isdigit() else None
    return None


def _write_without_blocking(port: serial.Serial, data: bytes) -> int:
    """
    Write what the device takes now; return the byte count (0 when its buffer is full).

    pyserial 3.5's ``write`` with ``write_timeout=0`` retries EAGAIN in a loop, so a device that
    stops reading (a hung board that stays enumerated, a stopped fish_sim) would spin the caller
    forever once the kernel's buffer fills. The descriptor is non-blocking: write to it directly.
    Ports without a descriptor (test doubles) use their own ``write``.
    """
    try:
        fd = port.fileno()
    except (AttributeError, serial.SerialException):
        written: int = port.write(data)  # pyserial has no types
        return written
    try:
        return os.write(fd, data)
    except BlockingIOError:
        return 0
