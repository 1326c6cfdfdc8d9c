# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish's end of a pseudo-terminal pair, with a stable symlink to the device.

``open_pair`` makes a new pty pair (raw mode), and atomically re-points the symlink (``link``)
to its slave device, so a bridge that opens the link path always finds the current device, as with
/dev/serial/by-id/ for a real board. ``close`` removes the link (if it is still ours) and then
closes both ends, which the bridge sees as EIO on its old descriptor (the device was
"unplugged", and like a by-id link its link is gone until it is back). The link never points at
a closed device: its pts number may be taken by another terminal, or another virtual fish, at
once.

Beside the link, an owner record (``wirefish_bridge.link_owner``) names this process and the
device, written before the link is re-pointed: if this process is killed and its pts number is
reused by another terminal, a bridge sees that the link is stale and does not open it.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
import tty

from wirefish_bridge.link_owner import remove_owner_record, write_owner_record


class PtyDevice:
    """Master side of a pty pair; non-blocking reads and writes."""

    def __init__(self, link: Path | None = None) -> None:
        """Remember the symlink path (None: no symlink)."""
        self.link = link
        self.path: str | None = None
        self._master: int | None = None
        self._slave: int | None = None

    @property
    def is_open(self) -> bool:
        """Return True while a pty pair is open."""
        return self._master is not None

    def fileno(self) -> int:
        """Return the master descriptor (for select)."""
        if self._master is None:
            raise OSError(errno.EBADF, 'pty is closed')
        return self._master

    def open_pair(self) -> str:
        """Open a new pty pair, point the symlink at it and return the slave device path."""
        master, slave = os.openpty()
        # Raw mode before anyone opens the slave: no echo, no CR/LF translation of our bytes.
        tty.setraw(slave)
        os.set_blocking(master, False)
        self._master, self._slave = master, slave
        self.path = os.ttyname(slave)
        if self.link is not None:
            write_owner_record(self.link, self.path)
            temporary = self.link.with_name(f'.{self.link.name}.{os.getpid()}')
            if temporary.is_symlink():
                temporary.unlink()
            os.symlink(self.path, temporary)
            os.replace(temporary, self.link)  # atomic: the link never dangles mid-update
        return self.path

    def close(self) -> None:
        """Remove our link, then close both ends (the peer's reads fail with EIO)."""
        self.remove_link()
        for fd in (self._master, self._slave):
            if fd is not None:
                os.close(fd)
        self._master = self._slave = None

    def remove_link(self) -> None:
        """Remove the symlink and its owner record if the link still points at our device."""
        if self.link is not None and self.link.is_symlink() and self.path is not None:
            if os.readlink(self.link) == self.path:
                self.link.unlink()
                remove_owner_record(self.link)

    def read(self, size: int = 4096) -> bytes:
        """Return the bytes the peer wrote (b'' if none or if closed)."""
        if self._master is None:
            return b''
        try:
            return os.read(self._master, size)
        except (BlockingIOError, InterruptedError):
            return b''
        except OSError as error:
            if error.errno == errno.EIO:   # no peer has the slave open
                return b''
            raise

    def write(self, data: bytes) -> int:
        """Write without blocking; return how many bytes the pty took (0 when full/closed)."""
        if self._master is None:
            return 0
        try:
            return os.write(self._master, data)
        except (BlockingIOError, InterruptedError):
            return 0
