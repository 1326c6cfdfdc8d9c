# SPDX-License-Identifier: Apache-2.0
"""
`make test` deals the longest modules first, shares the machine by slots, ends a hung run.

A test that hangs where no signal reaches it: pytest-timeout (``timeout`` in pytest.ini)
interrupts a test by SIGALRM, whose handler is Python code, and a thread waiting in C code for
good (seen once: a probe's DDS participant destroyed while a peer was being discovered, Fast
DDS's teardown waiting on its own listener) never runs it. pytest's own faulthandler timeout,
later, dumps every thread's stack and ends that worker from C; xdist then reports the test as
crashed, and with ``--max-worker-restart 0`` ends the run (xdist 3.8's loadfile scheduling gives
a replacement worker the crashed test again, and a run once waited on that for good).
"""

import configparser
import fcntl
import json
import os
from pathlib import Path
import re
import subprocess
import sys
import threading
import time

from machine_share import (heavy_weight, machine_share, module_weight, Share, slot_count,
                           SLOTS_VARIABLE)
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


def _graph_run_words() -> list[str]:
    """
    Return the command line `make test` runs test/ with, as words.

    `make -n` prints the commands without running them; a `make test` around this one (the
    suite's own run) passes its command-line variables down in MAKEFLAGS: left out here.
    """
    env = {k: v for k, v in os.environ.items() if k not in ('MAKEFLAGS', 'MFLAGS', 'MAKELEVEL')}
    commands = subprocess.run(['make', '-n', 'test', 'PYTEST_ARGS='], cwd=WORKSPACE, env=env,
                              capture_output=True, text=True, check=True).stdout
    # One shell line runs both pytest runs (the pure tests in the background): its commands.
    shell_commands = re.split(r'[;&]', commands.replace('\\\n', ' '))
    return next(command for command in shell_commands
                if '--no-loadscope-reorder' in command).split()


def test_make_test_deals_files_in_collection_order():
    # Without --no-loadscope-reorder xdist deals the files with most tests first, and the
    # one-test long modules come last whatever the collection order.
    run = _graph_run_words()
    assert '--no-loadscope-reorder' in run and 'test' in run


MODULE_ON_ONE_WORKER = """
import os
from pathlib import Path

import pytest


@pytest.mark.parametrize('k', range(6))
def test_says_its_worker(k):
    Path(os.environ['WORKERS_SEEN'], f'{k}.txt').write_text(os.environ['PYTEST_XDIST_WORKER'])
"""


def test_a_modules_tests_stay_on_one_worker_under_any_n(tmp_path):
    # A module's graph is module-scoped, under the module's namespace: on two workers it would
    # be started twice under one name (pytest.ini's --dist loadfile, for `make test` and for a
    # developer's `pytest -n 2 test/bringup/test_restart.py` alike).
    (tmp_path / 'test_module.py').write_text(MODULE_ON_ONE_WORKER)
    seen = tmp_path / 'seen'
    seen.mkdir()
    subprocess.run([sys.executable, '-m', 'pytest', '-c', str(WORKSPACE / 'pytest.ini'),
                    '--rootdir', str(tmp_path), '-n', '2', '-q',
                    str(tmp_path / 'test_module.py')],
                   cwd=tmp_path, env={**os.environ, 'WORKERS_SEEN': str(seen)},
                   capture_output=True, text=True, check=True, timeout=120)
    workers = {path.read_text() for path in seen.glob('*.txt')}
    assert len(list(seen.glob('*.txt'))) == 6 and len(workers) == 1


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


@pytest.mark.parametrize('weight', [-1, 4])
def test_a_weight_outside_zero_to_the_slots_is_refused(tmp_path, weight):
    with pytest.raises(ValueError, match='0 to 3 of 3'):
        with machine_share(tmp_path, 3, weight):
            pass


@pytest.mark.parametrize('slots', [2, 3, 4])
def test_a_module_that_loads_the_machine_leaves_one_slot_to_the_rest(slots):
    assert heavy_weight(slots) == slots - 1


@pytest.mark.parametrize('slots', [1, 2, 3, 4])
def test_a_module_that_keeps_the_machine_holds_every_slot(slots):
    assert module_weight(Share.KEEPS, slots) == slots


def test_the_markers_weigh_every_slot_all_but_one_none_and_one():
    assert [module_weight(share, 3) for share in Share] == [3, 2, 0, 1]


def test_on_one_slot_a_module_that_loads_the_machine_holds_it():
    assert heavy_weight(1) == 1


def test_a_module_that_barely_loads_the_machine_runs_while_every_slot_is_held(tmp_path):
    events: list = []
    holders = [_hold(tmp_path, 3, 1, events, f'm{i}', 1.0) for i in range(3)]
    _wait_for(lambda: len(events) == 3)  # every slot held for a second more
    barely = _hold(tmp_path, 3, 0, events, 'barely', 0.0)
    barely.join(timeout=30.0)
    for thread in holders:
        thread.join(timeout=30.0)
    ran = [t for t, name, _ in events if name == 'barely']
    freed = [t for t, name, change in events if change < 0]
    assert len(ran) == 2 and max(ran) < min(freed)  # in and out before any slot came free


HOLDER = """
import threading
import time

from machine_share import machine_share


def pytest_sessionstart(session):
    # Every slot of the run, held by another worker's module for a while.
    run_directory = session.config._tmp_path_factory.getbasetemp()
    held = threading.Event()

    def hold():
        with machine_share(run_directory, 1, 1):
            held.set()
            time.sleep({hold_s})
    threading.Thread(target=hold, daemon=True).start()
    held.wait()
"""
QUICK = """
def test_quick():
    pass
"""


def test_a_modules_wait_for_its_slots_is_not_its_tests_time(tmp_path):
    # A module waiting for the slots other workers' modules hold is not hung: pytest-timeout's
    # timer (which counts a test's setup) starts once the slots are the module's.
    timeout_s, hold_s = 2, 5
    (tmp_path / 'slot_holder.py').write_text(HOLDER.format(hold_s=hold_s))
    (tmp_path / 'test_quick.py').write_text(QUICK)
    env = {k: v for k, v in os.environ.items() if not k.startswith('PYTEST_XDIST')}
    env.update(PYTHONPATH=os.pathsep.join(
        [str(tmp_path), str(WORKSPACE / 'test'), str(WORKSPACE / 'test' / 'support'),
         env.get('PYTHONPATH', '')]),
        **{SLOTS_VARIABLE: '1'})
    # The suite's conftest as a plugin, for a module outside test/ (and a holder of the slots).
    run = subprocess.run([sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider',
                          '-p', 'conftest', '-p', 'slot_holder', '-o', f'timeout={timeout_s}',
                          '--basetemp', str(tmp_path / 'run'), str(tmp_path / 'test_quick.py')],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    print(run.stdout[-3000:])
    assert run.returncode == 0
    logged = [json.loads(line) for line in (tmp_path / 'run' / 'machine_share.jsonl').open()]
    assert [m['module'] for m in logged] == ['test_quick.py']
    assert logged[0]['waited_s'] > timeout_s


def test_the_configured_slots_are_one_to_the_workers():
    assert slot_count(4, '3') == 3 and slot_count(1, '1') == 1 and slot_count(3) == 3
    with pytest.raises(ValueError, match='1 to 4 slots for 4 workers'):
        slot_count(4, '5')


def _make_test_words(*variables: str) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k not in ('MAKEFLAGS', 'MFLAGS', 'MAKELEVEL')}
    commands = subprocess.run(['make', '-n', 'test', 'PYTEST_ARGS=', *variables], cwd=WORKSPACE,
                              env=env, capture_output=True, text=True, check=True).stdout
    return commands.replace('\\\n', ' ').split()


@pytest.mark.parametrize('slots, workers', [('3', '4'), ('2', '3'), ('1', '1')])
def test_make_test_runs_a_worker_beyond_the_slots_for_barely_loading_modules(slots, workers):
    words = _make_test_words(f'GRAPH_SLOTS={slots}')
    graph_run = words.index('--no-loadscope-reorder') - 2  # ... -n WORKERS --no-loadscope...
    assert words[graph_run:graph_run + 2] == ['-n', workers]
    assert f'WIREFISH_MACHINE_SLOTS={slots}' in words


HANG = """
import ctypes


def test_hangs_in_c_code():
    # A default mutex locked twice by its owner: the thread waits in the kernel for good.
    libc = ctypes.CDLL(None)
    mutex = ctypes.create_string_buffer(64)  # more than a pthread_mutex_t
    libc.pthread_mutex_init(mutex, None)
    libc.pthread_mutex_lock(mutex)
    libc.pthread_mutex_lock(mutex)
"""
TIMEOUT_S, FAULTHANDLER_S = 1, 4  # the suite's two timeouts, shortened


def _suite_ini() -> configparser.SectionProxy:
    ini = configparser.ConfigParser()
    ini.read(WORKSPACE / 'pytest.ini')
    return ini['pytest']


def test_the_faulthandler_timeout_comes_after_pytest_timeouts_and_ends_the_worker():
    ini = _suite_ini()
    assert float(ini['faulthandler_timeout']) > float(ini['timeout'])
    assert ini.getboolean('faulthandler_exit_on_timeout')


def test_a_test_hung_in_c_code_fails_and_the_run_ends(tmp_path):
    (tmp_path / 'test_hang.py').write_text(HANG)
    (tmp_path / 'pytest.ini').write_text(
        f'[pytest]\ntimeout = {TIMEOUT_S}\nfaulthandler_timeout = {FAULTHANDLER_S}\n'
        f"faulthandler_exit_on_timeout = {_suite_ini()['faulthandler_exit_on_timeout']}\n")
    words = _graph_run_words()
    options = [w for w in words[words.index('pytest') + 1:] if w != 'test']
    run = subprocess.run([sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider', *options,
                          str(tmp_path)], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120)
    print(run.stdout[-3000:])
    assert run.returncode == 1
    assert "crashed while running 'test_hang.py::test_hangs_in_c_code'" in run.stdout
    assert f'Timeout (0:00:0{FAULTHANDLER_S})!' in run.stdout + run.stderr  # the stacks
