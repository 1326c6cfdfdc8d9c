# SPDX-License-Identifier: Apache-2.0
"""
SIGINT (once or twice) each node executable at a random moment of its start-up; count the clean.

    tools/wfenv python tools/probes/startup_sigint.py --runs 50 [--within 3.0] [--domain 92]
        [--started-by wirefish-up|ros2-launch|ros2-run]

For every run and node: start it (the installed executable, the default params file, a
namespace of its own), wait a random time in [0, ``--within``) s, send SIGINT (and, every other
run, a second one 50 ms later), and wait for its exit. Clean: exit code 0 and no
"Traceback"/"KeyboardInterrupt" in its output. Prints the unclean ones with the delay and the
end of their output, and a summary per node; exit code 0 only if all were clean.

``--started-by wirefish-up`` (the default) starts each node through `wirefish up`'s own
``Supervisor`` (stop signals blocked until the node's handler is in place); ``ros2-launch``
through the launch file's prefix (``held_start_prefix``: env blocks them, then execs the node;
env's own first milliseconds are the window left); ``ros2-run`` as `ros2 run` does, with
SIGINT's default disposition (the interpreter's start-up and the entry script's imports are
then a window nothing of ours can close).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time


from ament_index_python.packages import get_package_share_directory
import numpy as np
from wirefish_bringup.graph import NodeSpec
from wirefish_common.startup_signals import held_start_prefix
from wirefish_launcher.supervisor import Supervisor

NODES = (('wirefish_cpg', 'cpg_node'), ('wirefish_tuner', 'tuner_node'),
         ('wirefish_kinematics', 'kinematics_node'), ('wirefish_planner', 'planner_node'),
         ('wirefish_bridge', 'bridge_node'), ('wirefish_tf', 'tf_node'))
EXIT_TIMEOUT_S = 30.0


def _sigint_default() -> None:
    """
    Give the node SIGINT's default disposition, as a terminal's or a launcher's child has.

    A disposition of SIG_IGN survives exec: started from a background job of a non-interactive
    shell (`tool &`), which ignores SIGINT, a node's interpreter keeps ignoring it until the
    node's package installs its own handler, and a SIGINT sent before that is lost (the node
    then runs until killed). That is the shell's choice, not the node's start-up: measured here
    it would count as a hang.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _spec(package: str, name: str, namespace: str) -> NodeSpec:
    params = Path(get_package_share_directory('wirefish_bringup'), 'config', 'wirefish.yaml')
    return NodeSpec(package, name, name, namespace=namespace, params_file=str(params))


def _start(spec: NodeSpec, env: dict[str, str], started_by: str,
           logs: Path) -> tuple[subprocess.Popen, Path | None]:
    """Start one node; return it and its log file (None: its output is on its stdout pipe)."""
    if started_by == 'wirefish-up':
        supervisor = Supervisor(logs, env=env)
        return supervisor.start(spec), logs / f'{spec.name}.log'
    command = [str(spec.executable_path()), *spec.command_arguments()]
    if started_by == 'ros2-launch':
        command = [*shlex.split(held_start_prefix() or ''), *command]
    return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, preexec_fn=_sigint_default), None


def main() -> int:
    """Run every node ``--runs`` times; print the unclean runs and a summary."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--runs', type=int, default=50, help='runs per node (default %(default)s)')
    parser.add_argument('--within', type=float, default=3.0,
                        help='the SIGINT comes within this many seconds of the start '
                             '(default %(default)s)')
    parser.add_argument('--domain', type=int, default=92, help='ROS domain (default %(default)s)')
    parser.add_argument('--seed', type=int, default=0, help='seed of the delays')
    parser.add_argument('--started-by', choices=('wirefish-up', 'ros2-launch', 'ros2-run'),
                        default='wirefish-up', help='how each node is started '
                        '(default %(default)s)')
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    env = dict(os.environ, ROS_DOMAIN_ID=str(args.domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')
    unclean = 0
    for package, name in NODES:
        clean = 0
        for run in range(args.runs):
            delay = float(rng.uniform(0.0, args.within))
            twice = run % 2 == 1
            logs = Path(tempfile.mkdtemp(prefix='startup_sigint_'))
            proc, log = _start(_spec(package, name, f'/startup_{run}'), env, args.started_by,
                               logs)
            time.sleep(delay)
            proc.send_signal(signal.SIGINT)
            if twice:
                time.sleep(0.05)
                if proc.poll() is None:
                    proc.send_signal(signal.SIGINT)
            try:
                output, _ = proc.communicate(timeout=EXIT_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                proc.kill()
                output, _ = proc.communicate()
            if log is not None:
                output = log.read_text(errors='replace')
            shutil.rmtree(logs)
            ok = proc.returncode == 0 and 'Traceback' not in output \
                and 'KeyboardInterrupt' not in output
            clean += ok
            if not ok:
                print(f'{name} run {run + 1}: SIGINT{" x2" if twice else ""} at {delay:.2f} s -> '
                      f'exit {proc.returncode}\n    ' + '\n    '.join(output.splitlines()[-4:]),
                      flush=True)
        unclean += args.runs - clean
        print(f'{name}: {clean}/{args.runs} clean (started by {args.started_by}; SIGINT within '
              f'{args.within:g} s of the start, every other run twice; load '
              f'{os.getloadavg()[0]:.1f})', flush=True)
    return 0 if unclean == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
