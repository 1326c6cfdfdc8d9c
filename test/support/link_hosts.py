# SPDX-License-Identifier: Apache-2.0
"""
The two-host tests' helpers: probe processes on one host, the pair's processes, waiting.

See conftest.py for the fixture that makes the hosts.
"""

from dataclasses import dataclass, field
import json
import os
from pathlib import Path
import subprocess
import sys
import threading
import time

PROBE = str(Path(__file__).with_name('link_probe.py'))


class Probe:
    """A link_probe process on one host: its JSON lines, collected by a thread."""

    def __init__(self, proc: subprocess.Popen) -> None:
        """Start reading the probe's output."""
        self.proc = proc
        self.lines: list[dict] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for text in self.proc.stdout:
            try:
                line = json.loads(text)
            except ValueError:
                print('probe:', text.rstrip())
                continue
            with self._lock:
                self.lines.append(line)

    def snapshot(self) -> list[dict]:
        """Return the lines so far."""
        with self._lock:
            return list(self.lines)

    def reports(self) -> list[dict]:
        """Return the periodic count reports so far."""
        return [line for line in self.snapshot() if 'counts' in line]

    def events(self, name: str) -> list[dict]:
        """Return the event lines of ``name`` (cpg_params, planner_state)."""
        return [line for line in self.snapshot() if line.get('event') == name]

    def send(self, command: str) -> None:
        """Write one steering line (go SPEED YAW / halt)."""
        self.proc.stdin.write(command + '\n')
        self.proc.stdin.flush()


@dataclass
class Hosts:
    """The pair, the ROS environment of each side and the processes started on them."""

    link: object
    domain_id: int
    namespace: str
    out: Path
    discovery: str
    processes: list = field(default_factory=list)

    def env(self, side: str) -> dict[str, str]:
        """Return the environment of a process on ``side``."""
        return dict(os.environ, ROS_DOMAIN_ID=str(self.domain_id), PYTHONUNBUFFERED='1',
                    RCUTILS_COLORIZED_OUTPUT='0',
                    **self.link.ros_environment(side, self.discovery))

    def start(self, side: str, args: list[str], **kwargs) -> subprocess.Popen:
        """Start ``args`` on ``side``'s host (its own process group, stopped at teardown)."""
        kwargs.setdefault('stdout', subprocess.PIPE)
        kwargs.setdefault('stderr', subprocess.STDOUT)
        proc = subprocess.Popen(self.link.exec_prefix(side) + args, env=self.env(side),
                                text=True, start_new_session=True, **kwargs)
        self.processes.append(proc)
        return proc

    def run(self, side: str, args: list[str], timeout_s: float) -> subprocess.CompletedProcess:
        """Run ``args`` on ``side``'s host to its end; return its result."""
        return subprocess.run(self.link.exec_prefix(side) + args, env=self.env(side),
                              capture_output=True, text=True, timeout=timeout_s)

    def probe(self, side: str, *topics: str) -> Probe:
        """Start a link_probe on ``side`` subscribed to ``topics`` (TOPIC:TYPE:QOS)."""
        return Probe(self.start(side, [sys.executable, PROBE, self.namespace, *topics],
                                stdin=subprocess.PIPE, stderr=subprocess.DEVNULL))

    def up(self, side: str, role: str) -> subprocess.Popen:
        """Start `wirefish up --role ROLE` on ``side``'s host (logs under ``out``)."""
        return self.start(side, ['wirefish', 'up', '--role', role, '--namespace',
                                 self.namespace, '--no-status', '--out', str(self.out)])


def wait_for(predicate, timeout_s: float, what: str) -> float:
    """Poll ``predicate`` until true; return the monotonic time it became true, or fail."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, f'{what}: not within {timeout_s:g} s'
        time.sleep(0.1)
    return time.monotonic()
