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


def start_graph(domain_id: int, out_dir: Path, *options: str) -> RunningGraph:
    """Start `wirefish up --sim [options]` (the launcher behind `make run`) on its own domain."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    launcher = subprocess.Popen(
        [sys.executable, '-m', 'wirefish_bringup.cli', 'up', '--sim', '--no-status',
         '--namespace', NAMESPACE, '--out', str(out_dir), *options],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        line = launcher.stdout.readline()
        if not line:
            break
        if line.startswith('running:'):
            return RunningGraph(launcher, env, domain_id, NAMESPACE, out_dir)
    stop_process(launcher)
    raise RuntimeError('wirefish up did not start: ' + launcher.stdout.read())


def descendants(pid: int) -> list[psutil.Process]:
    """Return every live descendant process of ``pid``."""
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []
