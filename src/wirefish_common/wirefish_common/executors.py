# SPDX-License-Identifier: Apache-2.0
"""
Which rclpy executor spins a wirefish process, and the one loop that spins it.

``events`` (the default): ``rclpy.experimental.EventsExecutor``, the C++ events-based executor
the pinned Jazzy wheel (rclpy 7.1.6) ships. A wake-up of rclpy's Python executors costs a few
hundred microseconds of Python before any callback runs (docs/PROFILING.md); this one's does
not. ``classic``: ``SingleThreadedExecutor``, the fallback. The environment chooses:
``WIREFISH_EXECUTOR=events|classic`` (`wirefish up` passes its environment to every node, so
one variable switches a whole graph).

What holds on the events executor (probed on this wheel): timers, subscriptions, publishers,
services and clients, parameter services, and ``create_task`` from any thread (it wakes the
executor within 0.1-0.3 ms). What does not: guard conditions (``RuntimeError: Guard conditions
not supported``), coroutine callbacks (a service that awaits another service's answer: the
tuner keeps a ``MultiThreadedExecutor``), and ``spin()`` while rclpy is shut down from another
thread, which hangs the process. Hence the one way a wirefish process spins, whichever the
executor: ``spin_until_stopped``, ``spin_once`` in a loop in the main thread until a stop flag
is set; whoever sets the flag calls ``wake`` (a no-op task) so the loop sees it at once; the
context is shut down after the loop, never under it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
import enum
import os
import time
from typing import Any

EXECUTOR_VARIABLE = 'WIREFISH_EXECUTOR'


class ExecutorKind(enum.StrEnum):
    """The executors a wirefish process spins on (the values of ``WIREFISH_EXECUTOR``)."""

    EVENTS = 'events'  # the default
    CLASSIC = 'classic'


# The longest the loop goes without looking at its stop flag if nobody wakes it.
SPIN_TIMEOUT_S = 0.1
# The longest ``settle`` spins: callbacks already queued run first, each a few ms at most.
SETTLE_S = 2.0


def executor_kind(environ: Mapping[str, str] | None = None) -> ExecutorKind:
    """Return the executor kind ``WIREFISH_EXECUTOR`` names (unset or empty: events)."""
    environ = os.environ if environ is None else environ
    value = environ.get(EXECUTOR_VARIABLE, '').strip() or ExecutorKind.EVENTS
    try:
        return ExecutorKind(value)
    except ValueError:
        raise ValueError(f'{EXECUTOR_VARIABLE}={value!r} is not an executor: expected one of '
                         f'{", ".join(ExecutorKind)}') from None


def make_executor(kind: str, context: Any = None) -> Any:
    """Return a new executor of ``kind`` (an ``ExecutorKind``) on ``context``."""
    if kind == ExecutorKind.EVENTS:
        from rclpy.experimental import EventsExecutor
        return EventsExecutor(context=context)
    if kind == ExecutorKind.CLASSIC:
        from rclpy.executors import SingleThreadedExecutor
        return SingleThreadedExecutor(context=context)
    raise ValueError(f'unknown executor kind {kind!r}: expected one of '
                     f'{", ".join(ExecutorKind)}')


def spin_until_stopped(executor: Any, stopped: Callable[[], bool]) -> None:
    """
    Spin ``executor`` one callback at a time until ``stopped()``.

    Nothing else is asked between two callbacks: a ``context.ok()`` there was 15 % of the
    bridge's Python samples at its ~300 callbacks a second. A context shut down under the
    loop still ends it: ``spin_once`` then raises (``ExternalShutdownException`` on both
    executors, or rcl's error on a classic executor whose guard is gone).
    """
    while not stopped():
        executor.spin_once(timeout_sec=SPIN_TIMEOUT_S)


def settle(executor: Any, timeout_s: float = SETTLE_S) -> bool:
    """
    Spin ``executor`` until everything handed to it before this call has run; return whether.

    Both executors run their queued work in order: a task queued now runs after what
    ``remove_node`` asked for (the events executor lets go of a removed node's entities in a
    handler it queues, behind whatever callbacks were already waiting, so one ``spin_once``
    may run one of those instead). False if ``timeout_s`` went by first.
    """
    done: list[bool] = []
    executor.create_task(lambda: done.append(True))
    deadline = time.monotonic() + timeout_s
    while not done and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=SPIN_TIMEOUT_S)
    return bool(done)


def _nothing() -> None:
    """Do nothing: the task only ends the executor's wait."""


def wake(executor: Any) -> None:
    """Make ``executor``'s current or next ``spin_once`` return (safe from any thread)."""
    executor.create_task(_nothing)
