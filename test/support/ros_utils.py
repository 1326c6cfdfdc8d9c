# SPDX-License-Identifier: Apache-2.0
"""Helpers for tests that drive ROS nodes and child processes."""

from collections.abc import Callable
import os
from pathlib import Path
import signal
import subprocess
import time

# The helper processes of the cross-process tests (a BodyWave talker, a RetuneGait server).
PEERS = str(Path(__file__).with_name('ros_peers.py'))


def spin_until(executor, predicate: Callable[[], bool], timeout_s: float) -> bool:
    """Spin ``executor`` until ``predicate()`` is true or ``timeout_s`` passes; return it."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        executor.spin_once(timeout_sec=0.05)
    return predicate()


def stop_process(proc: subprocess.Popen, timeout_s: float = 5.0) -> int | None:
    """SIGINT the process group, wait, then SIGKILL it; return the exit code (None if killed)."""
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGINT)
        except ProcessLookupError:
            pass
        try:
            return proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            pass
    else:
        return proc.returncode
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()
    return None
