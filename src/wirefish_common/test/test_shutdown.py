# SPDX-License-Identifier: Apache-2.0
"""A process that hangs in its stop writes its threads' stacks; one that stops in time, nothing."""

import signal
import subprocess
import sys
import textwrap

import pytest

# Stops after the signal, either at once or through a function that hangs for 3 s; writes its
# stacks if the stop takes longer than argv[2] seconds.
_PROCESS = textwrap.dedent("""
    import sys
    import time
    from wirefish_common.shutdown import SignalShutdown

    signals = SignalShutdown(stacks_after_s=float(sys.argv[2]))
    print('ready', flush=True)
    while not signals.requested:
        time.sleep(0.01)

    def a_stop_that_hangs():
        time.sleep(3.0)

    if sys.argv[1] == 'hang':
        a_stop_that_hangs()
""")


# A stop at once is in time by far even on a starved machine: beside two CPU hogs a process
# told 0.5 s once took longer than that to leave after its signal, and wrote its stacks.
_HANG_ALLOWANCE_S = 0.5
_IN_TIME_ALLOWANCE_S = 10.0


def _stop(mode: str, signum: int) -> tuple[int, str]:
    allowance = _HANG_ALLOWANCE_S if mode == 'hang' else _IN_TIME_ALLOWANCE_S
    proc = subprocess.Popen([sys.executable, '-c', _PROCESS, mode, str(allowance)],
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline() == 'ready\n'
        proc.send_signal(signum)
        _, stderr = proc.communicate(timeout=30.0)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return proc.returncode, stderr


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
def test_a_stop_that_hangs_writes_where_it_hangs(signum):
    code, stderr = _stop('hang', signum)
    assert code == 0
    assert 'a_stop_that_hangs' in stderr, stderr


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM])
def test_a_stop_in_time_writes_nothing(signum):
    code, stderr = _stop('at once', signum)
    assert code == 0
    assert stderr == ''


# Three threads besides the main one, the last started after the main thread's CPUs are printed
# and before the teardown starts ('teardown'), or while the process is pinned to one CPU, before
# the CPUs are given back ('restore'); then every thread's CPUs, a line each.
_THREADS = textwrap.dedent("""
    import os
    import sys
    import threading
    from wirefish_common.shutdown import begin_teardown, restore_cpus, threads_on_one_cpu

    def cpus(task):
        return ' '.join(str(cpu) for cpu in sorted(os.sched_getaffinity(task)))

    stop = threading.Event()
    workers = [threading.Thread(target=stop.wait) for _ in range(3)]
    workers[0].start()
    workers[1].start()
    print(cpus(0))
    if sys.argv[1] == 'teardown':
        workers[2].start()
        begin_teardown(seconds=30.0)
    else:
        before = threads_on_one_cpu()
        workers[2].start()
        restore_cpus(before)
    for task in sorted(os.listdir('/proc/self/task')):
        print(cpus(int(task)))
    stop.set()
    for worker in workers:
        worker.join()
""")


def _thread_cpus(mode: str) -> tuple[str, list[str]]:
    """Return the CPUs the process started with and those of each of its threads after."""
    done = subprocess.run([sys.executable, '-c', _THREADS, mode], capture_output=True,
                          text=True, timeout=30.0)
    assert done.returncode == 0, done.stderr
    started_with, *after = done.stdout.splitlines()
    assert len(after) >= 4, done.stdout  # the main thread and the three workers
    return started_with, after


def test_the_teardown_puts_every_thread_on_one_cpu():
    _, after = _thread_cpus('teardown')
    assert len(set(after)) == 1 and len(after[0].split()) == 1, after


def test_every_thread_gets_its_cpus_back():
    started_with, after = _thread_cpus('restore')
    assert set(after) == {started_with}, after
