# SPDX-License-Identifier: Apache-2.0
"""
How test/'s modules share the machine: weighed slots taken through a turnstile.

Most of test/ waits on graphs (real-time ones, or simulated ones paced at real time), so `make
test` runs more workers than the machine has cores; but a few modules load the machine
themselves (busy loops beside a recording, an emulated STM32, a browser), and beside two other
modules their real-time streams starved (seen with three workers: a failsafe of the QEMU board,
a recording 1.8 s behind, a dashboard that never plotted). So the machine has as many slots as
workers (at least two): a module holds one slot while it runs, a module that loads the machine
holds all but one (``heavy_weight``: one light module runs beside it), and those modules run one
at a time. Slots are lock files shared by the run's workers; a module takes its slots through a
turnstile lock, so a module that needs several is not overtaken by ones that need one.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager, ExitStack
import fcntl
from pathlib import Path
import time
from typing import IO

POLL_S = 0.2


def slot_count(workers: int) -> int:
    """Return the machine's slots for a run of ``workers`` workers (at least two)."""
    return max(2, workers)


def heavy_weight(slots: int) -> int:
    """Return the slots a module that loads the machine holds: all but one."""
    return slots - 1


@contextmanager
def _locked(path: Path) -> Iterator[IO[str]]:
    with open(path, 'a') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield lock
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _try_slot(path: Path, stack: ExitStack) -> bool:
    """Take the slot at ``path`` if it is free (held until ``stack`` closes)."""
    lock = open(path, 'a')
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:  # another module's, or one of this module's own two
        lock.close()
        return False
    stack.enter_context(lock)
    stack.callback(fcntl.flock, lock, fcntl.LOCK_UN)
    return True


@contextmanager
def machine_share(directory: Path, slots: int, weight: int) -> Iterator[None]:
    """Hold ``weight`` of the ``slots`` slots kept in ``directory`` while inside."""
    if not 1 <= weight <= slots:
        raise ValueError(f'a module holds 1 to {slots} of {slots} slots, not {weight}')
    with ExitStack() as stack:
        if weight > 1:  # the modules that load the machine take turns
            stack.enter_context(_locked(directory / 'loads_machine.lock'))
        with _locked(directory / 'turnstile.lock'):
            held = 0
            while held < weight:
                for k in range(slots):
                    if held < weight and _try_slot(directory / f'slot_{k}.lock', stack):
                        held += 1
                if held < weight:
                    time.sleep(POLL_S)
        yield
