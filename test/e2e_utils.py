"""Helpers of the end-to-end tests: the whole graph started exactly as `make run` starts it."""

from dataclasses import dataclass
import os
from pathlib import Path
import subprocess
import sys
import time

import psutil
from ros_utils import stop_process

NAMESPACE = '/e2e'


@dataclass
class RunningGraph:
    """A `wirefish up` process and what the tests need to talk to its graph."""

    launcher: subprocess.Popen
    env: dict[str, str]
    domain_id: int
    namespace: str
    out_dir: Path


def start_graph(domain_id: int, out_dir: Path, *options: str,
                namespace: str = NAMESPACE, swimming: bool = True) -> RunningGraph:
    """
    Start `wirefish up --sim [options]` (the launcher behind `make run`) on its own domain.

    Give each test that starts a graph a ``namespace`` of its own: a graph that is still
    stopping in the same namespace would make the new `wirefish up` refuse to start.
    ``swimming``: with --start-swimming (the tests observe a swimming fish; `make run`'s fish
    starts still until its first command).
    """
    if swimming:
        options = ('--start-swimming', *options)
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    launcher = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--sim', '--no-status',
         '--namespace', namespace, '--out', str(out_dir), *options],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    deadline = time.monotonic() + 60.0
    seen = []
    try:
        while time.monotonic() < deadline:
            line = launcher.stdout.readline()
            if not line:
                break
            seen.append(line)
            if line.startswith(('running:', 'recording to ')):  # up, or up --duration
                return RunningGraph(launcher, env, domain_id, namespace, out_dir)
    except BaseException:  # Ctrl-C or a timeout while waiting: leave no graph behind
        stop_process(launcher)
        raise
    stop_process(launcher)
    raise RuntimeError('wirefish up did not start:\n' + ''.join(seen) + launcher.stdout.read())


def descendants(pid: int) -> list[psutil.Process]:
    """Return every live descendant process of ``pid``."""
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []
