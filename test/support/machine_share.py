# SPDX-License-Identifier: Apache-2.0
"""
How test/'s modules share the machine: weighed slots taken through a turnstile.

Most of test/ waits on graphs (real-time ones, or simulated ones paced at real time), so `make
test` runs more workers than the machine has cores; but a few modules load the machine
themselves (busy loops beside a recording, an emulated STM32, a browser), and beside two other
modules their real-time streams starved (seen with three workers: a failsafe of the QEMU board,
a recording 1.8 s behind, a dashboard that never plotted). So the machine has slots (as many as
workers, at least two, unless `make test` says how many: ``SLOTS_VARIABLE``): a module holds
one slot while it runs, a module that loads the machine holds all but one (``heavy_weight``: one
light module runs beside it), and those modules run one at a time. A module that barely loads
the machine (its graph or node mostly waits: on discovery, a service, a deadline, a few
messages; at most ~0.25 of a core in full runs) holds none: `make test` runs a worker more than
the slots for them. Slots are lock files shared by the run's workers; a module takes its slots
through a turnstile lock, so a module that needs several is not overtaken by ones that need one.
A module whose claims are on the wall clock of a stand-in for hardware (the radio model, the
board behind it: how soon a gait is acknowledged, how fast the fish swims over the radio)
keeps the machine to itself: it holds every slot, and only modules that barely load the machine
(and src/'s pure tests, at nice 5) run beside it: the stand-ins run on the wall clock, and a
starved one adds its own delays to those of the hardware it stands for.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager, ExitStack
import enum
import fcntl
from pathlib import Path
import time
from typing import IO

POLL_S = 0.2
# The slots `make test` gives the machine (its workers are one more: test/conftest.py).
SLOTS_VARIABLE = 'WIREFISH_MACHINE_SLOTS'


def slot_count(workers: int, configured: str | None = None) -> int:
    """
    Return the machine's slots for a run of ``workers`` workers.

    ``configured`` (``SLOTS_VARIABLE``'s value, from `make test`) if given: 1 to ``workers``.
    Else as many as the workers, at least two.
    """
    if configured is None:
        return max(2, workers)
    slots = int(configured)
    if not 1 <= slots <= max(1, workers):
        raise ValueError(f'{SLOTS_VARIABLE}={configured}: 1 to {max(1, workers)} slots for '
                         f'{workers} workers')
    return slots


def heavy_weight(slots: int) -> int:
    """Return the slots a module that loads the machine holds: all but one (one of one)."""
    return max(1, slots - 1)


class Share(enum.Enum):
    """How much of the machine a module takes: its marker (pytest.ini)."""

    KEEPS = 'keeps_machine'            # every slot
    LOADS = 'loads_machine'            # all but one
    BARELY = 'barely_loads_machine'    # none
    ONE = ''                           # unmarked: one


def module_weight(share: Share, slots: int) -> int:
    """Return the slots of ``slots`` a module of ``share`` holds."""
    return {Share.KEEPS: slots, Share.LOADS: heavy_weight(slots), Share.BARELY: 0,
            Share.ONE: 1}[share]


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
    """Hold ``weight`` of the ``slots`` slots kept in ``directory`` while inside (0: none)."""
    if not 0 <= weight <= slots:
        raise ValueError(f'a module holds 0 to {slots} of {slots} slots, not {weight}')
    if weight == 0:  # a module that barely loads the machine runs beside the slots' modules
        yield
        return
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
