# SPDX-License-Identifier: Apache-2.0
"""
A test that hangs where no signal reaches it fails, and `make test`'s run of test/ ends.

pytest-timeout (``timeout`` in pytest.ini) interrupts a test by SIGALRM, whose handler is Python
code: a thread waiting in C code for good (seen once: a probe's DDS participant destroyed while
a peer was being discovered, Fast DDS's teardown waiting on its own listener) never runs it.
pytest's own faulthandler timeout, later, dumps every thread's stack and ends that worker from
C; xdist then reports the test as crashed, and with ``--max-worker-restart 0`` ends the run
(xdist 3.8's loadfile scheduling gives a replacement worker the crashed test again, and a run
once waited on that for good).
"""

import configparser
from pathlib import Path
import subprocess
import sys

WORKSPACE = Path(__file__).resolve().parents[1]
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


def _graph_run_options() -> list[str]:
    """Return the options `make test` runs test/ with (`make -n` prints without running)."""
    commands = subprocess.run(['make', '-n', 'test'], cwd=WORKSPACE, capture_output=True,
                              text=True, check=True).stdout.replace('\\\n', ' ')
    words = next(line for line in commands.splitlines() if '--dist loadfile' in line).split()
    return [w for w in words[words.index('pytest') + 1:] if w != 'test']


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
    run = subprocess.run([sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider',
                          *_graph_run_options(), str(tmp_path)], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    print(run.stdout[-3000:])
    assert run.returncode == 1
    assert "crashed while running 'test_hang.py::test_hangs_in_c_code'" in run.stdout
    assert f'Timeout (0:00:0{FAULTHANDLER_S})!' in run.stdout + run.stderr  # the stacks
