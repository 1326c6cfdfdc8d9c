# SPDX-License-Identifier: Apache-2.0
"""
The fish's board in an emulator: the firmware's ARM build on ``qemu-system-arm``.

QEMU's ``netduinoplus2`` machine is an STM32F405 (the Cortex-M4F family of the fish's
STM32F407). ``-serial pty`` puts its USART1, the link to the host, on a pseudo-terminal that
QEMU names on its output ("char device redirected to /dev/pts/N (label serial0)"); a second
``-serial pty`` puts USART2, the emulator build's debug console (firmware/port/stm32f4), on
another. A ``QemuBoard`` starts QEMU, finds both, publishes the link under a stable symlink
(the bridge's ``port``: a restarted QEMU gets another /dev/pts number, the symlink is repointed
and the bridge's transport reopens the same path) and stops QEMU with SIGTERM, then SIGKILL,
leaving no process behind: QEMU also gets SIGTERM when the process that started it dies.

`wirefish qemu` (``wirefish_launcher.verb.qemu``) runs one board until Ctrl-C.
"""

from __future__ import annotations

from collections import deque
import ctypes
from dataclasses import dataclass
import fcntl
import os
from pathlib import Path
import re
import select
import shutil
import signal
import subprocess
import threading
import time
from types import TracebackType

from wirefish_launcher.errors import QemuBoardError

QEMU = 'qemu-system-arm'
MACHINE = 'netduinoplus2'
IMAGE = Path('build', 'qemu', 'wirefish.elf')  # relative to firmware/
START_TIMEOUT_S = 10.0
TERM_GRACE_S = 3.0
_PTY_LINE = re.compile(r'char device redirected to (/dev/pts/\d+) \(label serial(\d+)\)')
_PR_SET_PDEATHSIG = 1
BUILD_LOCK = '.make.lock'  # in the firmware's build/: whoever runs make there takes it
INSTALL_HINT = ('install it with `make setup` as root (apt: gcc-arm-none-eabi '
                'libnewlib-arm-none-eabi qemu-system-arm)')


def firmware_dir() -> Path:
    """
    Return the firmware source tree: ``$WIREFISH_FIRMWARE_DIR`` or the repository's firmware/.

    The package is installed with --symlink-install, so this module resolves into the source
    tree, whose firmware/ is three levels up from the package directory.
    """
    configured = os.environ.get('WIREFISH_FIRMWARE_DIR')
    if configured:
        return Path(configured)
    return Path(__file__).resolve().parents[3] / 'firmware'


def build_image(directory: Path | None = None) -> Path:
    """
    Build the emulator image (``make -C firmware qemu``) if it is out of date; return its path.

    Raises QemuBoardError with one line: the missing tool, or the build's first error. Builds
    of one tree take turns (a lock file in its build/): two at once, two boards started side by
    side on a fresh tree, wrote the same objects and one linked the other's half-written ones.
    """
    directory = firmware_dir() if directory is None else directory
    if not (directory / 'Makefile').is_file():
        raise QemuBoardError(f'no firmware source tree at {directory} (set '
                             "WIREFISH_FIRMWARE_DIR to the repository's firmware/)")
    if shutil.which('make') is None:
        raise QemuBoardError('make not found: install it (apt-get install make)')
    (directory / 'build').mkdir(exist_ok=True)
    with open(directory / 'build' / BUILD_LOCK, 'w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        result = subprocess.run(['make', '--no-print-directory', '-C', str(directory), 'qemu'],
                                capture_output=True, text=True)
    if result.returncode != 0:
        raise QemuBoardError('the emulator image did not build: '
                             + _first_error(result.stderr or result.stdout))
    return directory / IMAGE


def _first_error(output: str) -> str:
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    for line in lines:
        if 'error' in line.lower() or 'not found' in line:
            return line
    return lines[-1] if lines else 'make failed without a message'


def _die_with_parent() -> None:  # in the child, between fork and exec
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)


def qemu_command(image: Path, serials: int) -> list[str]:
    """Return QEMU's command line: the image on netduinoplus2, ``serials`` USARTs on ptys."""
    command = [QEMU, '-M', MACHINE, '-kernel', str(image), '-nographic', '-monitor', 'none']
    for _ in range(serials):
        command += ['-serial', 'pty']
    return command


@dataclass(frozen=True)
class BoardPorts:
    """The pseudo-terminals of one running QEMU: USART1 (the link), USART2 (the console)."""

    link: str
    console: str | None


class QemuBoard:
    """
    One emulated board: start, find its ptys, publish the link symlink, stop.

    ``link``: the symlink to point at USART1's pty (None: none); ``console``: also put the
    debug console (USART2) on a pty. Use as a context manager, or call ``start``/``stop``.
    """

    def __init__(self, image: Path, *, link: Path | None = None, console: bool = False) -> None:
        """Configure the board; nothing runs before ``start``."""
        self.image = image
        self.link = link
        self.console = console
        self.ports: BoardPorts | None = None
        self._proc: subprocess.Popen[bytes] | None = None
        self._output: deque[str] = deque(maxlen=50)
        self._drain: threading.Thread | None = None

    @property
    def pid(self) -> int | None:
        """Return QEMU's pid while it runs, else None."""
        proc = self._proc
        return proc.pid if proc is not None and proc.poll() is None else None

    def running(self) -> bool:
        """Return True while QEMU runs."""
        return self._proc is not None and self._proc.poll() is None

    def start(self, timeout_s: float = START_TIMEOUT_S) -> BoardPorts:
        """Start QEMU and wait until it names its ptys; publish the link; return the ports."""
        if self.running():
            raise QemuBoardError('the board is already running')
        if shutil.which(QEMU) is None:
            raise QemuBoardError(f'{QEMU} not found: {INSTALL_HINT}')
        if not self.image.is_file():
            raise QemuBoardError(f'no firmware image at {self.image}: run make -C firmware qemu')
        serials = 2 if self.console else 1
        self._output.clear()
        self._proc = subprocess.Popen(qemu_command(self.image, serials),
                                      stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT,
                                      start_new_session=True, preexec_fn=_die_with_parent)
        try:
            found = self._read_ptys(serials, timeout_s)
        except BaseException:
            self.stop()
            raise
        self.ports = BoardPorts(found[0], found.get(1))
        self._drain = threading.Thread(target=self._drain_output, name='qemu-output',
                                       daemon=True)
        self._drain.start()
        if self.link is not None:
            point_link(self.link, self.ports.link)
        return self.ports

    def _read_ptys(self, serials: int, timeout_s: float) -> dict[int, str]:
        assert self._proc is not None and self._proc.stdout is not None
        found: dict[int, str] = {}
        deadline = time.monotonic() + timeout_s
        fd = self._proc.stdout.fileno()  # read unbuffered: select must see what is unread
        pending = b''
        while len(found) < serials:
            left = deadline - time.monotonic()
            if left <= 0:
                raise QemuBoardError(f'{QEMU} named no pty within {timeout_s:g} s: '
                                     + ' | '.join(self._output))
            if not select.select([fd], [], [], min(left, 0.2))[0]:
                continue
            chunk = os.read(fd, 4096)
            if not chunk:
                code = self._proc.wait()
                raise QemuBoardError(f'{QEMU} exited with code {code} before naming its pty: '
                                     + (' | '.join(self._output) or 'no output'))
            *lines, pending = (pending + chunk).split(b'\n')
            for raw in lines:
                line = raw.decode(errors='replace').rstrip()
                self._output.append(line)
                match = _PTY_LINE.search(line)
                if match:
                    found[int(match.group(2))] = match.group(1)
        return found

    def _drain_output(self) -> None:
        """Keep QEMU's output pipe empty (a full pipe would stop it); keep the last lines."""
        proc = self._proc
        if proc is None or proc.stdout is None:
            return
        fd = proc.stdout.fileno()
        while True:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                return
            if not chunk:
                return
            self._output.extend(chunk.decode(errors='replace').splitlines())

    def output(self) -> str:
        """Return QEMU's last output lines (for error messages)."""
        return '\n'.join(self._output)

    def stop(self, timeout_s: float = TERM_GRACE_S) -> int | None:
        """SIGTERM QEMU, SIGKILL it after ``timeout_s``; return its exit code (None: killed)."""
        proc, self._proc = self._proc, None
        if proc is None:
            return None
        code: int | None
        if proc.poll() is None:
            _signal_group(proc, signal.SIGTERM)
            try:
                code = proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                _signal_group(proc, signal.SIGKILL)
                proc.wait()
                code = None
        else:
            code = proc.returncode
        if self._drain is not None:
            self._drain.join(1.0)
            self._drain = None
        if proc.stdout is not None:
            proc.stdout.close()
        return code

    def restart(self, timeout_s: float = START_TIMEOUT_S) -> BoardPorts:
        """Stop QEMU and start it again (a power cycle); the link symlink is repointed."""
        self.stop()
        return self.start(timeout_s)

    def remove_link(self) -> None:
        """Remove the link symlink if it points at this board's pty."""
        if self.link is not None and self.link.is_symlink():
            self.link.unlink()

    def __enter__(self) -> QemuBoard:
        """Start the board."""
        self.start()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 trace: TracebackType | None) -> None:
        """Stop the board and remove its link."""
        self.stop()
        self.remove_link()


def _signal_group(proc: subprocess.Popen[bytes], signum: int) -> None:
    try:
        os.killpg(proc.pid, signum)
    except ProcessLookupError:
        pass


def point_link(link: Path, target: str) -> None:
    """Point the symlink ``link`` at ``target`` in one step (a reader never sees it missing)."""
    temporary = link.with_name(f'.{link.name}.{os.getpid()}')
    if temporary.is_symlink():
        temporary.unlink()
    os.symlink(target, temporary)
    os.replace(temporary, link)
