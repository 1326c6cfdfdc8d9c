# SPDX-License-Identifier: Apache-2.0
"""A process that hangs in its stop writes its threads' stacks; one that stops in time, nothing."""

import signal
import subprocess
import sys
import textwrap

import pytest

# Stops after the signal, either at once or through a function that hangs for 3 s.
_PROCESS = textwrap.dedent("""
    import sys
    import time
    from wirefish_common.shutdown import SignalShutdown

    signals = SignalShutdown(stacks_after_s=0.5)
    print('ready', flush=True)
    while not signals.requested:
        time.sleep(0.01)

    def a_stop_that_hangs():
        time.sleep(3.0)

    if sys.argv[1] == 'hang':
        a_stop_that_hangs()
""")


def _stop(mode: str, signum: int) -> tuple[int, str]:
    proc = subprocess.Popen([sys.executable, '-c', _PROCESS, mode], stdout=subprocess.PIPE,
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


# Three threads besides the main one, then the teardown's start; prints each thread's CPUs.
_TEARDOWN = textwrap.dedent("""
    import os
    import threading
    from wirefish_common.shutdown import begin_teardown

    stop = threading.Event()
    workers = [threading.Thread(target=stop.wait) for _ in range(3)]
    for worker in workers:
        worker.start()
    begin_teardown(seconds=30.0)
    for task in sorted(os.listdir('/proc/self/task')):
        print(' '.join(str(cpu) for cpu in sorted(os.sched_getaffinity(int(task)))))
    stop.set()
    for worker in workers:
        worker.join()
""")


def test_the_teardown_puts_every_thread_on_one_cpu():
    done = subprocess.run([sys.executable, '-c', _TEARDOWN], capture_output=True, text=True,
                          timeout=30.0)
    assert done.returncode == 0, done.stderr
    affinities = done.stdout.splitlines()
    assert len(affinities) >= 4  # the main thread and the three workers
    assert len(set(affinities)) == 1 and len(affinities[0].split()) == 1, affinities


# Pins, starts a thread while pinned, gives the CPUs back; prints each thread's CPUs after.
_PIN_AND_RESTORE = textwrap.dedent("""
    import os
    import threading
    from wirefish_common.shutdown import restore_cpus, threads_on_one_cpu

    stop = threading.Event()
    workers = [threading.Thread(target=stop.wait) for _ in range(2)]
    workers[0].start()
    print(' '.join(str(cpu) for cpu in sorted(os.sched_getaffinity(0))))
    before = threads_on_one_cpu()
    workers[1].start()  # made while the process is on one CPU
    restore_cpus(before)
    for task in sorted(os.listdir('/proc/self/task')):
        print(' '.join(str(cpu) for cpu in sorted(os.sched_getaffinity(int(task)))))
    stop.set()
    for worker in workers:
        worker.join()
""")


def test_every_thread_gets_its_cpus_back():
    done = subprocess.run([sys.executable, '-c', _PIN_AND_RESTORE], capture_output=True,
                          text=True, timeout=30.0)
    assert done.returncode == 0, done.stderr
    started_with, *after = done.stdout.splitlines()
    assert len(after) >= 3  # the main thread and both workers
    assert set(after) == {started_with}, done.stdout
