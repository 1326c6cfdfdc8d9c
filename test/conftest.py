# SPDX-License-Identifier: Apache-2.0
"""
Fixtures shared by the workspace-level tests: ROS isolation and child processes.

Every test that touches ROS gets its own ``ROS_DOMAIN_ID`` (and its own rclpy context), so
tests never hear each other's traffic, and every child process is started in its own process
group and torn down (SIGINT, then SIGKILL) when the test ends, so none is left behind.
"""

from collections.abc import Callable, Iterator
from contextlib import ExitStack
import itertools
import json
import os
from pathlib import Path
import subprocess
import sys
import time

from machine_share import machine_share, module_weight, Share, slot_count, SLOTS_VARIABLE
from module_order import module_rank
import pytest
from ros_utils import domain_context, stop_process

WORKSPACE = Path(__file__).resolve().parents[1]
# Fast DDS maps a domain to UDP ports; 0..101 is the portable range. A test run owns the window
# [base, base + 20): each test takes the next of the first 19 ids (so a test never shares a
# domain with the one before it); base + 19 is kept for module-scoped graphs (test/bringup).
# Under pytest-xdist (`make test` runs test/ on a worker more than the cores, at most four)
# worker k owns the next window, [base + 20 k, base + 20 k + 20): set here, before any conftest
# or test module reads it.
_WORKER = os.environ.get('PYTEST_XDIST_WORKER', '')
if _WORKER.startswith('gw'):
    os.environ['WIREFISH_TEST_DOMAIN_BASE'] = str(
        int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 20 * int(_WORKER[2:]))
_DOMAIN_BASE = int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21'))
_domains = itertools.cycle(range(_DOMAIN_BASE, _DOMAIN_BASE + 19))


@pytest.fixture(autouse=True, scope='session')
def nodes_destroyed_on_one_cpu() -> Iterator[None]:
    """
    Destroy every rclpy node of this test process with the process's threads on one CPU.

    The last node of a context deletes its DDS participant, and Fast DDS 2.14 can spin there,
    holding a mutex a discovery thread on the other core needs, for as long as that thread
    misses it (``wirefish_common.shutdown.begin_teardown``, where the nodes' own processes do
    the same): a worker once hung 20 minutes in a probe's ``destroy_node`` beside two busy
    loops. Each thread gets its CPUs back once the node is gone.
    """
    from rclpy.node import Node
    from wirefish_common.shutdown import restore_cpus, threads_on_one_cpu

    destroy_node = Node.destroy_node

    def destroy_node_on_one_cpu(node: Node) -> None:
        before = threads_on_one_cpu()
        try:
            destroy_node(node)
        finally:
            restore_cpus(before)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(Node, 'destroy_node', destroy_node_on_one_cpu)
        yield


@pytest.fixture(autouse=True)
def isolated_ros_home(tmp_path_factory: pytest.TempPathFactory,
                      monkeypatch: pytest.MonkeyPatch) -> Path:
    """
    Give every test a ROS home of its own (``ROS_HOME``), for itself and its child processes.

    The tuner's gait library defaults to ``$ROS_HOME/wirefish/gaits.yaml``: with the user's
    ``~/.ros`` a test would answer from a fit that an earlier run stored, or leave one behind.
    """
    home = tmp_path_factory.mktemp('ros_home')
    monkeypatch.setenv('ROS_HOME', str(home))
    return home


@pytest.fixture
def ros_domain_id() -> int:
    """Return a ROS domain id that no other test in this run is using."""
    return next(_domains)


@pytest.fixture
def ros_env(ros_domain_id: int) -> dict[str, str]:
    """Return an environment for child ROS processes, isolated to this test's domain."""
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = str(ros_domain_id)
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONUNBUFFERED'] = '1'
    env['RCUTILS_COLORIZED_OUTPUT'] = '0'
    return env


@pytest.fixture
def ros_context(ros_domain_id: int) -> Iterator[object]:
    """Yield an initialised rclpy context of its own, on this test's domain."""
    with domain_context(ros_domain_id) as context:
        yield context


@pytest.fixture
def spawn(ros_env: dict[str, str]) -> Iterator[Callable[..., subprocess.Popen]]:
    """
    Start child processes on this test's domain; every one is stopped when the test ends.

    ``spawn(args, **popen_kwargs)`` returns the ``Popen``; stdout and stderr go to a pipe
    (merged) unless overridden.
    """
    procs: list[subprocess.Popen] = []

    def _spawn(args: list[str], **kwargs) -> subprocess.Popen:
        kwargs.setdefault('env', ros_env)
        kwargs.setdefault('stdout', subprocess.PIPE)
        kwargs.setdefault('stderr', subprocess.STDOUT)
        kwargs.setdefault('text', True)
        proc = subprocess.Popen(args, start_new_session=True, **kwargs)
        procs.append(proc)
        return proc

    yield _spawn
    for proc in procs:
        stop_process(proc)
        for stream in (proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()


class _ModuleShare:
    """The machine share (machine_share.py) a test/ module holds while its tests run."""

    def __init__(self, module: pytest.Module, run_directory: Path) -> None:
        workers = int(os.environ.get('PYTEST_XDIST_WORKER_COUNT', '1'))
        slots = slot_count(workers, os.environ.get(SLOTS_VARIABLE))
        share = next((share for share in Share
                      if share.value and module.get_closest_marker(share.value)), Share.ONE)
        self.weight = module_weight(share, slots)
        self.module, self.run_directory = module, run_directory
        self._stack = ExitStack()
        asked = time.monotonic()
        self._stack.enter_context(machine_share(run_directory, slots, self.weight))
        self.started, self.started_at = time.monotonic(), time.time()
        self.waited_s = self.started - asked
        self.cpu_before = _cpu_seconds()

    def leave(self) -> None:
        """Give the share back; log what the module waited, held and cost (one JSON line)."""
        # One line per module: what `make test`'s time is made of (waits and holds).
        with open(self.run_directory / 'machine_share.jsonl', 'a') as log:
            log.write(json.dumps({'module': self.module.nodeid, 'weight': self.weight,
                                  'started_at': round(self.started_at, 2),
                                  'waited_s': round(self.waited_s, 2),
                                  'held_s': round(time.monotonic() - self.started, 2),
                                  'cpu_s': round(_cpu_seconds() - self.cpu_before, 2)}) + '\n')
        self._stack.close()


_share: _ModuleShare | None = None  # the share of the module whose tests this process runs


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    """
    Run each module on its share of the machine (machine_share.py): its marker's slots.

    The slots are shared by the run's workers (lock files in the run's base temp); mark a
    module that loads the machine itself ``pytest.mark.loads_machine`` (all slots but one), one
    whose claims are on a hardware stand-in's wall clock ``pytest.mark.keeps_machine`` (every
    slot), one that barely loads it ``pytest.mark.barely_loads_machine`` (no slot). The share
    is taken before the module's first test starts, outside pytest-timeout's timer (which
    counts setup): a wait for the other workers' modules is not the test's time. It is given
    back once the module's last test ended and its module fixtures with it.
    """
    global _share
    module = item.getparent(pytest.Module)
    if _share is None and module is not None:
        # The tmp_path_factory fixture's object: a hook has no fixtures. A worker's is popen-gwK.
        run_directory = item.config._tmp_path_factory.getbasetemp()
        _share = _ModuleShare(module, run_directory.parent if _WORKER else run_directory)
    yield
    if _share is not None and (nextitem is None or nextitem.getparent(pytest.Module)
                               is not _share.module):
        _share.leave()
        _share = None


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Give back the share of a module a stopped run (-x, Ctrl-C) left in the middle."""
    global _share
    if _share is not None:
        _share.leave()
        _share = None


def _cpu_seconds() -> float:
    """Return this worker's CPU time with that of the children it has reaped (and theirs)."""
    times = os.times()
    return times.user + times.system + times.children_user + times.children_system


@pytest.fixture
def python() -> str:
    """Return the interpreter running the tests (the workspace venv's)."""
    return sys.executable


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Collect the longest modules first (module_order.py); every other test keeps its place."""
    items.sort(key=lambda item: module_rank(Path(item.fspath)))


_RUN_STARTED = time.monotonic()


def pytest_terminal_summary(terminalreporter, exitstatus: int, config: pytest.Config) -> None:
    """
    Say what the run cost the machine: CPU seconds of every process it reaped, against its wall.

    The CPU over the cores is the least wall time any dealing of the modules could reach on this
    machine: a run whose CPU is near it is bound by the CPU, not by its slots.
    """
    if _WORKER:
        return
    times = os.times()
    cpu_s = times.user + times.system + times.children_user + times.children_system
    wall_s = time.monotonic() - _RUN_STARTED
    cores = len(os.sched_getaffinity(0))
    terminalreporter.write_line(
        f'machine: {cpu_s:.0f} CPU s in {wall_s:.0f} s on {cores} core(s): '
        f'{cpu_s / max(wall_s * cores, 1e-9):.0%} of them; on these cores at least '
        f'{cpu_s / cores:.0f} s')
