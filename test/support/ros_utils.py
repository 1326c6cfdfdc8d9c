# SPDX-License-Identifier: Apache-2.0
"""Helpers for tests that drive ROS nodes and child processes."""

from collections.abc import Callable, Iterator
from contextlib import contextmanager
import os
from pathlib import Path
import signal
import subprocess
import time

# The helper processes of the cross-process tests (a BodyWave talker, a RetuneGait server).
PEERS = str(Path(__file__).with_name('ros_peers.py'))


@contextmanager
def domain_context(domain_id: int) -> Iterator[object]:
    """
    Yield an initialised rclpy context of its own on ``domain_id``; shut it down after.

    Discovery stays on this host (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` while it is open),
    as every graph a test starts.
    """
    import pytest
    import rclpy
    from rclpy.context import Context

    with pytest.MonkeyPatch.context() as monkeypatch:
        monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        context = Context()
        rclpy.init(context=context, domain_id=domain_id)
        try:
            yield context
        finally:
            rclpy.try_shutdown(context=context)


@contextmanager
def probe_node(name: str, context) -> Iterator[tuple]:
    """Yield (node, executor): a test's own node on ``context``, spun by hand; closed after."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    node = rclpy.create_node(name, context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        yield node, executor
    finally:
        executor.shutdown()
        node.destroy_node()


def stop_signals_blocked_soon(pid: int, timeout_s: float = 10.0) -> bool:
    """Wait until process ``pid`` has SIGINT and SIGTERM blocked; return whether it did."""
    from wirefish_common.startup_signals import stop_signals_blocked

    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if stop_signals_blocked(Path(f'/proc/{pid}/status').read_text()):
            return True
        time.sleep(0.0005)
    return False


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
