# SPDX-License-Identifier: Apache-2.0
"""
Start the graph's processes, watch them, and stop every one of them cleanly.

What `ros2 launch` does for a full install, in plain subprocess calls: each node is a child in
its own session (so a terminal's Ctrl-C reaches only the supervisor, which then sends exactly one
SIGINT to each child, in reverse start order), with a parent-death signal (so no child outlives
a supervisor that was killed) and, for the registry's executables, SIGINT/SIGTERM blocked until
the child's handler is in place (``wirefish_common.startup_signals``: no stop is lost or turned
into a trace during start-up), its output in a log file of its own, restarted by its restart
policy when it exits while the graph runs.
"""

from collections.abc import Sequence
import ctypes
import os
from pathlib import Path
import signal
import subprocess
import time
from typing import TextIO

from wirefish_bringup.graph import NodeSpec, RestartBudget
from wirefish_common.startup_signals import block_stop_signals

_PR_SET_PDEATHSIG = 1
TERM_GRACE_S = 2.0  # after the SIGTERM to a process still running at the stop's deadline
# The exit code of a node that refuses its start-up parameters (after one FATAL line).
CONFIGURATION_EXIT_CODE = 1


def _die_with_parent() -> None:  # runs in the child between fork and exec
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)


def _die_with_parent_holding_stops() -> None:  # the same, for a process that releases them
    _die_with_parent()
    # A stop that comes while the child's interpreter starts waits for the child's own handler
    # instead of ending it with a KeyboardInterrupt trace (NodeSpec.releases_stop_signals).
    block_stop_signals()


class ProcessExitedError(RuntimeError):
    """A required process of the graph exited and its restart budget is spent."""


class Supervisor:
    """
    Owns the graph's child processes from start to clean stop, restarting them by policy.

    ``supervise()`` answers the exits since its last call with each process's restart policy
    (see ``wirefish_bringup.graph``); call it from the thread that started the processes (the
    parent-death signal is tied to that thread).
    """

    def __init__(self, log_dir: Path, env: dict[str, str] | None = None) -> None:
        self._log_dir = log_dir
        self._env = dict(os.environ if env is None else env)
        self._env.setdefault('PYTHONUNBUFFERED', '1')
        self._env.setdefault('RCUTILS_COLORIZED_OUTPUT', '0')
        self.processes: dict[str, subprocess.Popen[bytes]] = {}
        self.specs: dict[str, NodeSpec] = {}
        self.budgets: dict[str, RestartBudget] = {}
        self.given_up: dict[str, int] = {}  # key -> its last exit code
        self._pending: dict[str, float] = {}  # key -> when (monotonic) it is restarted
        self._logs: dict[str, TextIO] = {}
        self.overran: list[str] = []  # the processes still running at stop()'s deadline

    def start(self, spec: NodeSpec) -> subprocess.Popen[bytes]:
        """
        Start one process of the graph; its output goes to ``<log_dir>/<key>.log``.

        The key is the spec's name, made unique (``bridge_node_2`` ...) when several fish run
        under one supervisor, so every process is tracked and stopped.
        """
        executable = spec.executable_path()
        if not executable.is_file():
            raise FileNotFoundError(f'{spec.package}/{spec.executable} is not installed at '
                                    f'{executable}: run `make setup`')
        key, n = spec.name, 1
        while key in self.processes:
            n += 1
            key = f'{spec.name}_{n}'
        self.specs[key] = spec
        self.budgets[key] = RestartBudget(spec.restart)
        return self._launch(key)

    def _launch(self, key: str) -> subprocess.Popen[bytes]:
        spec = self.specs[key]
        for link in spec.links:
            remove_stale_link(link)
        log = self._logs.get(key)
        if log is None:
            self._log_dir.mkdir(parents=True, exist_ok=True)
            log = self._logs[key] = open(self._log_dir / f'{key}.log', 'w', buffering=1)
        else:  # a restart: the same log, marked
            log.write(f'--- {key} restarted by wirefish up ---\n')
        proc = subprocess.Popen([str(spec.executable_path()), *spec.command_arguments()],
                                env=self._env, stdin=subprocess.DEVNULL, stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True,
                                preexec_fn=(_die_with_parent_holding_stops
                                            if spec.releases_stop_signals
                                            else _die_with_parent))
        self.processes[key] = proc
        return proc

    def exited(self) -> dict[str, int]:
        """Return the processes that have exited, with their exit codes."""
        return {name: proc.returncode for name, proc in self.processes.items()
                if proc.poll() is not None}

    def down(self) -> list[str]:
        """Return the processes not running now that are not given up (exited or restarting)."""
        return [key for key, proc in self.processes.items()
                if key not in self.given_up and (key in self._pending or proc.poll() is not None)]

    def supervise(self, now: float | None = None) -> list[str]:
        """
        Answer each exit since the last call by its policy; return one report line per event.

        An exited process is restarted after its policy's delay, or given up once its budget
        is spent; a given-up ``required`` process raises ProcessExitedError (the graph stops).
        """
        now = time.monotonic() if now is None else now
        lines = []
        for key, proc in self.processes.items():
            if key in self._pending or key in self.given_up or proc.poll() is None:
                continue
            spec, budget, code = self.specs[key], self.budgets[key], proc.returncode
            for link in spec.links:  # a killed virtual fish leaves its links behind
                remove_stale_link(link)
            refusal = self.refusal(key) if code == CONFIGURATION_EXIT_CODE else None
            if refusal is not None:
                # A node that refuses its start-up parameters refuses them again at every
                # restart: a configuration error, said on the terminal, never restarted.
                self.given_up[key] = code
                what = (f'{key} refused its start-up parameters and is not restarted (fix '
                        f'the parameter file and start again): {refusal}')
                if spec.restart.required:
                    raise ProcessExitedError(f'{what}; it is required: stopping the graph')
                lines.append(f'{what}; the rest keeps running')
                continue
            delay = budget.on_exit(now)
            if delay is not None:
                self._pending[key] = now + delay
                lines.append(f'{key} exited with code {code}; restarting it in {delay:g} s '
                             f'(restart {budget.in_window} of {spec.restart.max_restarts} '
                             f'within {spec.restart.window_s:g} s)')
                continue
            self.given_up[key] = code
            why = (f'after {budget.in_window} restarts within {spec.restart.window_s:g} s'
                   if spec.restart.respawn else 'and is not restarted (its policy)')
            if spec.restart.required:
                raise ProcessExitedError(
                    f'{key} exited with code {code} {why}; it is required: stopping the '
                    f'graph. Its log ({self._log_dir / (key + ".log")}) ends:\n'
                    + self.log_tail(key))
            lines.append(f'{key} exited with code {code} {why}: given up, the rest keeps '
                         f'running (log: {self._log_dir / (key + ".log")})')
        for key, due in list(self._pending.items()):
            if now >= due:
                del self._pending[key]
                lines.append(f'{key} restarted (pid {self._launch(key).pid})')
        return lines

    def summary(self) -> str | None:
        """Return one line of the restarts and given-up processes of the run, or None."""
        restarted = {key: b.total for key, b in self.budgets.items() if b.total}
        if not restarted and not self.given_up:
            return None
        parts = ['restarts: ' + (', '.join(f'{k} {n}' for k, n in restarted.items()) or 'none')]
        if self.given_up:
            parts.append('given up: ' + ', '.join(
                f'{k} (last exit code {code})' for k, code in self.given_up.items()))
        return '; '.join(parts)

    def refusal(self, key: str) -> str | None:
        """
        Return the FATAL reason the last start of ``key`` logged before it exited, or None.

        Every wirefish node logs one FATAL line and exits 1 when it refuses its start-up
        parameters (``wirefish_common.node_main``); a crash ends with a traceback instead.
        """
        path = self._log_dir / f'{key}.log'
        try:
            text = path.read_text(errors='replace')
        except OSError:
            return None
        last_start = text.rsplit(f'--- {key} restarted by wirefish up ---', 1)[-1]
        fatal = [line.split(']: ', 1)[-1] for line in last_start.splitlines()
                 if line.startswith('[FATAL]')]
        if not fatal or 'Traceback (most recent call last)' in last_start:
            return None
        return '; '.join(fatal)

    def log_tail(self, name: str, lines: int = 15) -> str:
        """Return the last lines of one process's log (for error messages)."""
        path = self._log_dir / f'{name}.log'
        try:
            return '\n'.join(path.read_text(errors='replace').splitlines()[-lines:])
        except OSError:
            return ''

    def stop(self, timeout_s: float = 5.0) -> dict[str, int | None]:
        """
        SIGINT every process (reverse start order), escalate after ``timeout_s``.

        A process still running then is named in ``overran`` and gets SIGTERM, then after
        ``TERM_GRACE_S`` SIGKILL. Returns each process's exit code: its own if it exited by
        itself (a wirefish process takes SIGTERM as one more stop request: exit 0 then means its
        stop was slow, not unclean), None if it had to be killed.
        """
        procs = list(self.processes.items())[::-1]
        for _, proc in procs:
            self._signal(proc, signal.SIGINT)
        deadline = time.monotonic() + timeout_s
        codes: dict[str, int | None] = {}
        for name, proc in procs:
            try:
                codes[name] = proc.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                self.overran.append(name)
                codes[name] = self._escalate(proc)
        self._pending.clear()  # stopping: a restart that was due never happens
        for log in self._logs.values():
            log.close()
        self._logs.clear()
        return codes

    def _escalate(self, proc: subprocess.Popen[bytes]) -> int | None:
        """SIGTERM, then SIGKILL after ``TERM_GRACE_S``; return its own exit code, or None."""
        self._signal(proc, signal.SIGTERM)
        try:
            return proc.wait(timeout=TERM_GRACE_S)
        except subprocess.TimeoutExpired:
            self._signal(proc, signal.SIGKILL)
            proc.wait()
            return None

    @staticmethod
    def _signal(proc: subprocess.Popen[bytes], signum: int) -> None:
        if proc.poll() is None:
            try:
                os.killpg(proc.pid, signum)
            except ProcessLookupError:
                pass


def remove_stale_link(link: Path) -> None:
    """
    Remove the pty symlink a killed virtual fish left behind, before starting a new one.

    A stale link may point at a /dev/pts number that another terminal has since taken: waiting
    for the link to exist would then succeed at once, and the bridge would talk to that terminal.
    """
    if link.is_symlink():
        link.unlink()


def wait_for_path(path: Path, procs: Sequence[subprocess.Popen[bytes]], timeout_s: float
                  ) -> bool:
    """Wait until ``path`` exists, giving up early if any of ``procs`` exits."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if path.exists():
            return True
        if any(proc.poll() is not None for proc in procs):
            return False
        time.sleep(0.05)
    return path.exists()
