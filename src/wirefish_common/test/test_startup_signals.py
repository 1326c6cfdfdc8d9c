# SPDX-License-Identifier: Apache-2.0
"""A process started through the held-start prefix has its stop signals blocked, not ignored."""

import shlex
import signal
import subprocess
import sys

from wirefish_common import startup_signals
from wirefish_common.startup_signals import (block_stop_signals, held_start_prefix,
                                             stop_signals_blocked)

REPORT = ('import signal\n'
          'blocked = signal.pthread_sigmask(signal.SIG_BLOCK, [])\n'
          'print(int(signal.SIGINT in blocked), int(signal.SIGTERM in blocked),\n'
          '      int(signal.getsignal(signal.SIGINT) is signal.default_int_handler))\n')


def _report(command_prefix: list[str], preexec=None) -> str:
    return subprocess.run([*command_prefix, sys.executable, '-c', REPORT], check=True,
                          capture_output=True, text=True, preexec_fn=preexec,
                          timeout=30.0).stdout.split()


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a background job's child


def test_the_prefix_exists_on_this_machine():
    assert held_start_prefix() is not None, 'coreutils env with --block-signal (>= 8.31)'


def test_through_the_prefix_both_are_blocked_and_sigint_has_its_default_action():
    assert _report(shlex.split(held_start_prefix()), _ignore_sigint) == ['1', '1', '1']


def test_a_launchers_child_has_both_blocked_and_sigint_its_default_action():
    def prepare() -> None:
        _ignore_sigint()
        block_stop_signals()
    assert _report([], prepare) == ['1', '1', '1']


def test_without_either_nothing_is_blocked():
    # SIGINT's default as a terminal's foreground child has it (a background job's is ignored).
    assert _report([], lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)) == ['0', '0', '1']


def test_an_env_that_does_not_block_gives_no_prefix(monkeypatch):
    monkeypatch.setattr(startup_signals, '_HELD_START', ('--default-signal=INT,TERM',))
    assert startup_signals.held_start_prefix() is None


def test_a_status_without_both_blocked_is_not_held():
    assert stop_signals_blocked('SigBlk:\t0000000000004002\n')
    assert not stop_signals_blocked('SigBlk:\t0000000000000002\n')
    assert not stop_signals_blocked('Name:\tx\n')
