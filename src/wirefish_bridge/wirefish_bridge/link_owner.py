# SPDX-License-Identifier: Apache-2.0
"""
Owner record of a virtual fish's symlink, so a bridge can tell a live link from a stale one.

A virtual fish points a symlink at its pseudo-terminal and writes ``<link>.owner`` beside it
(JSON: ``pid``, ``start``, the process's start time in clock ticks since boot, field 22 of
``/proc/<pid>/stat``, so a reused pid does not pass, and ``device``, the pty it points at).
A fish killed with SIGKILL cannot remove either; its pts number may later belong to an
unrelated terminal, and a bridge opening the link would configure and read that terminal.
Before opening a port the bridge asks ``stale_link_problem``: with a record beside the path,
the process it names must still be running and the path must still lead to the recorded
device; otherwise the link is stale and is not opened (the bridge retries: a new virtual fish
re-points the link and writes a new record). A port without a record (a real board's
/dev/serial/by-id/... path) is opened as before; the fish-heartbeat rule still guards writes.

``terminal_session`` covers the unrelated terminal itself, record or not: a device that is the
controlling terminal of a process (a shell in a terminal window, an ssh session) is not a fish,
and opening it would reconfigure it, flush its input and steal its keystrokes. ``open_refusal``
is both checks, the one a bridge runs before each open.

Linux (/proc); pure file reads, no rclpy. The virtual fish and the bridge must share a pid
namespace (they do when launched together).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import stat


def owner_record_path(link: Path) -> Path:
    """Return where the owner record of ``link`` is kept (beside it)."""
    return link.with_name(f'{link.name}.owner')


def process_start(pid: int) -> int | None:
    """Return the start time (clock ticks since boot) of process ``pid``, or None if none."""
    try:
        stat = Path(f'/proc/{pid}/stat').read_text(encoding='ascii', errors='replace')
    except OSError:
        return None
    # The name (field 2) may hold spaces and parentheses: the fields after it follow the last ')'.
    after_name = stat.rpartition(')')[2].split()
    try:
        return int(after_name[19])   # field 22 = the 20th after the name
    except (IndexError, ValueError):
        return None


def write_owner_record(link: Path, device: str, pid: int | None = None) -> None:
    """Record (atomically) that process ``pid`` (default: this one) serves ``device``."""
    pid = os.getpid() if pid is None else pid
    record = owner_record_path(link)
    temporary = record.with_name(f'.{record.name}.{os.getpid()}')
    temporary.write_text(json.dumps({'pid': pid, 'start': process_start(pid),
                                     'device': device}), encoding='utf-8')
    os.replace(temporary, record)


def remove_owner_record(link: Path) -> None:
    """Remove the owner record of ``link`` if there is one."""
    try:
        owner_record_path(link).unlink()
    except FileNotFoundError:
        pass


def stale_link_problem(port: str) -> str | None:
    """Return why ``port`` is a stale virtual-fish link that must not be opened, or None."""
    record_path = owner_record_path(Path(port))
    try:
        text = record_path.read_text(encoding='utf-8')
    except FileNotFoundError:
        return None   # not a virtual fish's link: the heartbeat rule decides
    except OSError as error:
        return f'owner record {record_path} unreadable ({error}): not opening {port}'
    try:
        record = json.loads(text)
        pid, start, device = int(record['pid']), record['start'], str(record['device'])
    except (ValueError, KeyError, TypeError) as error:
        return f'owner record {record_path} invalid ({error!r}): not opening {port}'
    if start is None or process_start(pid) != start:
        return (f'stale virtual-fish link: its owner (pid {pid}) is gone; not opening {port} '
                f'(now {os.path.realpath(port)}), waiting for a new virtual fish')
    if os.path.realpath(port) != os.path.realpath(device):
        return (f'stale virtual-fish link: {port} leads to {os.path.realpath(port)}, its owner '
                f'(pid {pid}) serves {device}; not opening it')
    return None


def terminal_session(port: str) -> tuple[int, str] | None:
    """
    Return (pid, command) of a process whose controlling terminal is the device at ``port``.

    None if there is none, or ``port`` is not a character device. Compares ``tty_nr`` of every
    ``/proc/<pid>/stat`` (field 7, the kernel's device encoding, which is ``st_rdev``'s).
    """
    try:
        info = os.stat(port)
    except OSError:
        return None
    if not stat.S_ISCHR(info.st_mode) or info.st_rdev == 0:
        return None
    try:
        entries = [entry.name for entry in os.scandir('/proc') if entry.name.isdigit()]
    except OSError:
        return None
    for name in entries:
        try:
            text = Path(f'/proc/{name}/stat').read_text(encoding='ascii', errors='replace')
        except OSError:
            continue   # the process ended meanwhile
        command, _, rest = text.partition(' (')[2].rpartition(')')
        fields = rest.split()   # state, ppid, pgrp, session, tty_nr, ...
        if len(fields) > 4 and fields[4].lstrip('-').isdigit() and int(fields[4]) == info.st_rdev:
            return int(name), command
    return None


def open_refusal(port: str) -> str | None:
    """Return why a bridge must not open ``port`` now (stale link, a terminal), or None."""
    problem = stale_link_problem(port)
    if problem is not None:
        return problem
    session = terminal_session(port)
    if session is not None:
        pid, command = session
        return (f'{port} ({os.path.realpath(port)}) is the controlling terminal of pid {pid} '
                f'({command}), not a fish: not opening it')
    return None
