# SPDX-License-Identifier: Apache-2.0
"""`make test` deals the longest modules first and shares the machine by slots."""

import fcntl
from pathlib import Path
import subprocess
import threading
import time

from machine_share import heavy_weight, machine_share, slot_count
from module_order import LONGEST_MODULES, module_rank
import pytest

WORKSPACE = Path(__file__).resolve().parents[1]


def test_every_longest_module_exists():
    missing = [name for name in LONGEST_MODULES if not (WORKSPACE / name).is_file()]
    assert not missing, f'renamed or gone (update LONGEST_MODULES): {missing}'


def test_the_longest_modules_rank_first_in_their_order():
    others = [WORKSPACE / 'test' / 'test_docs.py', WORKSPACE / 'test' / 'bridge' / 'test_a.py']
    paths = others + [WORKSPACE / name for name in reversed(LONGEST_MODULES)]
    ordered = sorted(paths, key=module_rank)
    assert ordered == [WORKSPACE / name for name in LONGEST_MODULES] + others


def test_make_test_deals_files_in_collection_order():
    # Without --no-loadscope-reorder xdist deals the files with most tests first, and the
    # one-test long modules come last whatever the collection order. `make -n` prints the
    # commands `make test` runs, without running them.
    commands = subprocess.run(['make', '-n', 'test'], cwd=WORKSPACE, capture_output=True,
                              text=True, check=True).stdout.replace('\\\n', ' ')
    run = next(line for line in commands.splitlines() if '--dist loadfile' in line)
    assert '--no-loadscope-reorder' in run.split() and 'test' in run.split()


def _hold(directory: Path, slots: int, weight: int, events: list, name: str,
          seconds: float) -> threading.Thread:
    def run() -> None:
        with machine_share(directory, slots, weight):
            events.append((time.monotonic(), name, +weight))
            time.sleep(seconds)
            events.append((time.monotonic(), name, -weight))
    thread = threading.Thread(target=run)
    thread.start()
    return thread


def _most_slots_held(events: list) -> int:
    held, most = 0, 0
    for _, _, change in sorted(events):
        held += change
        most = max(most, held)
    return most


def _wait_for(condition, timeout_s: float = 30.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, 'the holders did not get there in 30 s'
        time.sleep(0.01)


def _turnstile_held(directory: Path) -> bool:
    """Return whether a holder is inside the turnstile (flock: per open file, so seen here)."""
    with open(directory / 'turnstile.lock', 'a') as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(lock, fcntl.LOCK_UN)
        return False


@pytest.mark.parametrize('workers', [1, 2, 3, 4])
def test_modules_never_hold_more_slots_than_the_machine_has(tmp_path, workers):
    events: list = []
    slots = slot_count(workers)
    weights = [heavy_weight(slots), 1, 1, heavy_weight(slots), 1, 1, 1]
    threads = [_hold(tmp_path, slots, w, events, f'm{i}', 0.05)
               for i, w in enumerate(weights)]
    for thread in threads:
        thread.join(timeout=30.0)
    assert len(events) == 2 * len(weights)
    assert _most_slots_held(events) <= slots


def test_a_module_that_loads_the_machine_waits_for_two_free_slots(tmp_path):
    events: list = []
    # 'b' ends well after 'a': the slot 'a' frees is the only one the heavy module can take,
    # and none is left for the late one until the heavy one is done.
    first = _hold(tmp_path, 3, 1, events, 'a', 0.6)
    second = _hold(tmp_path, 3, 1, events, 'b', 1.5)
    # Wait on what happened, not on a sleep: a loaded machine starts threads late.
    _wait_for(lambda: len(events) == 2)  # both hold their slot: one of three is free
    heavy = _hold(tmp_path, 3, 2, events, 'heavy', 0.05)
    _wait_for(lambda: _turnstile_held(tmp_path))  # the heavy one waits in the turnstile
    late = _hold(tmp_path, 3, 1, events, 'late', 0.05)  # queues behind the heavy one
    for thread in (first, second, heavy, late):
        thread.join(timeout=30.0)
    starts = {name: t for t, name, change in events if change > 0}
    ends = {name: t for t, name, change in events if change < 0}
    assert starts['heavy'] >= min(ends['a'], ends['b'])
    assert starts['late'] >= starts['heavy']


@pytest.mark.parametrize('weight', [0, 4])
def test_a_weight_outside_one_to_the_slots_is_refused(tmp_path, weight):
    with pytest.raises(ValueError, match='1 to 3 of 3'):
        with machine_share(tmp_path, 3, weight):
            pass


@pytest.mark.parametrize('slots', [2, 3, 4])
def test_a_module_that_loads_the_machine_leaves_one_slot_to_the_rest(slots):
    assert heavy_weight(slots) == slots - 1
