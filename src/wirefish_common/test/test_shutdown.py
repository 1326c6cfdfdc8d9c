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
