# SPDX-License-Identifier: Apache-2.0
"""
SIGINT a whole `wirefish up` graph many times in a row; say how fast every process stopped.

    tools/wfenv python tools/probes/sigint_soak.py --runs 50 [--graphs 8] [--domain 90]
        [--discovery-range LOCALHOST] [--fleet 3 --swim-s 20]

Each round starts ``--graphs`` virtual-fish graphs at once (each its own namespace on one ROS
domain, the way eight users of one machine would; with ``--fleet N`` each a fleet of N fish),
waits until each says "running:" (and, with ``--swim-s``, lets the fish swim that long), sends
one SIGINT to each launcher (Ctrl-C), and watches every process of each graph until it is gone.
Per round: the slowest process's stop time after the SIGINT, the launchers' exit codes and the
codes they report for their processes. A process killed by the launcher's escalation (SIGTERM,
SIGKILL after its deadline) shows as a code other than 0. Prints one line per round and a
summary; exit code 0 only if every process of every round exited 0 within ``--bound`` s and
none was left.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import signal
import statistics
import subprocess
import sys
import tempfile
import time

import psutil

START_TIMEOUT_S = 180.0
WATCH_S = 30.0


def _start(index: int, domain: int, out: Path, discovery: str, fleet: int,
           swim: bool) -> subprocess.Popen:
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE=discovery,
               PYTHONUNBUFFERED='1')
    graph = ['--fleet', str(fleet)] if fleet else ['--sim']
    return subprocess.Popen(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', *graph, '--no-status',
         *(['--start-swimming'] if swim else []),
         '--namespace', f'/soak_{index}', '--out', str(out)],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        start_new_session=True)


def _wait_running(launcher: subprocess.Popen) -> list[str]:
    seen: list[str] = []
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        line = launcher.stdout.readline()
        if not line:
            break
        seen.append(line)
        if line.startswith('running:'):
            return seen
    raise RuntimeError('wirefish up did not start:\n' + ''.join(seen))


def _gone(proc: psutil.Process) -> bool:
    try:
        return not proc.is_running() or proc.status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


def _name(proc: psutil.Process) -> str:
    """Return a process's executable name (``python -m x``: x) for the round's line."""
    try:
        command = proc.cmdline()
    except psutil.Error:
        return '?'
    if not command:  # a process already exiting has no command line left
        return '?'
    if len(command) > 2 and command[1] == '-m':
        return command[2]
    return Path(command[1] if len(command) > 1 and 'python' in command[0] else command[0]).name


def one_round(graphs: int, domain: int, out: Path, discovery: str, fleet: int = 0,
              swim_s: float = 0.0) -> dict:
    """Start ``graphs`` graphs, SIGINT them, watch them stop; return the round's figures."""
    launchers = [_start(k, domain, out / f'g{k}', discovery, fleet, swim_s > 0.0)
                 for k in range(graphs)]
    try:
        for launcher in launchers:
            _wait_running(launcher)
        time.sleep(swim_s)
        children = {launcher.pid: psutil.Process(launcher.pid).children(recursive=True)
                    for launcher in launchers}
        sent = time.monotonic()
        for launcher in launchers:
            launcher.send_signal(signal.SIGINT)
        stopped_at: dict[int, float] = {}
        watched = [p for procs in children.values() for p in procs]
        names = {p.pid: _name(p) for p in watched}
        while len(stopped_at) < len(watched) and time.monotonic() - sent < WATCH_S:
            for proc in watched:
                if proc.pid not in stopped_at and _gone(proc):
                    stopped_at[proc.pid] = time.monotonic() - sent
            time.sleep(0.02)
        codes, reported, said = [], [], []
        for launcher in launchers:
            codes.append(launcher.wait(timeout=WATCH_S))
            rest = launcher.stdout.read()
            said += [x for x in rest.splitlines() if x.startswith('wirefish up:')]
            line = next((x for x in rest.splitlines() if x.startswith('stopped')), '')
            reported += [item.split('=')[1] for item in line.split(': ', 1)[-1].split(', ')
                         if '=' in item]
        left = [p.pid for p in watched if not _gone(p)]
        slowest = max(stopped_at, key=stopped_at.get, default=None)
        return {'processes': len(watched), 'slowest_s': max(stopped_at.values(), default=0.0),
                'slowest': names.get(slowest, '-'),
                'launcher_codes': codes, 'reported': reported, 'left': left, 'said': said}
    finally:  # a round that failed: the launchers stop their own processes, or all are killed
        for launcher in launchers:
            if launcher.poll() is None:
                launcher.send_signal(signal.SIGINT)
        for launcher in launchers:
            try:
                launcher.wait(timeout=WATCH_S)
            except subprocess.TimeoutExpired:
                for proc in psutil.Process(launcher.pid).children(recursive=True):
                    proc.kill()
                launcher.kill()
                launcher.wait()
            launcher.stdout.close()


def main() -> int:
    """Run the rounds; print one line each and a summary."""
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument('--runs', type=int, default=50, help='rounds (default %(default)s)')
    parser.add_argument('--graphs', type=int, default=1,
                        help='graphs started and stopped at once per round (default %(default)s)')
    parser.add_argument('--domain', type=int, default=90, help='ROS domain (default %(default)s)')
    # LOCALHOST makes rmw_fastrtps use shared memory whatever FASTDDS_BUILTIN_TRANSPORTS says;
    # SUBNET (rmw's default, what `wirefish up` gets unless the user sets a range) keeps UDPv4.
    parser.add_argument('--discovery-range', choices=('LOCALHOST', 'SUBNET'), default='SUBNET',
                        help='ROS_AUTOMATIC_DISCOVERY_RANGE of the graphs (default %(default)s)')
    parser.add_argument('--fleet', type=int, default=0,
                        help='fish per graph: `wirefish up --fleet N` (default: one, --sim)')
    parser.add_argument('--swim-s', type=float, default=0.0,
                        help='seconds the fish swim (--start-swimming) before the SIGINT '
                             '(default: stopped at once)')
    parser.add_argument('--bound', type=float, default=3.0,
                        help='seconds every process must stop within (default %(default)s)')
    args = parser.parse_args()
    if args.fleet < 0 or not 0.0 <= args.swim_s <= 3600.0:
        parser.error('--fleet is 0 (one fish, --sim) or more, --swim-s 0 to 3600')
    slowest, bad = [], 0
    with tempfile.TemporaryDirectory(prefix='wirefish_soak_') as tmp:
        for run in range(args.runs):
            figures = one_round(args.graphs, args.domain, Path(tmp) / f'r{run}',
                                args.discovery_range, args.fleet, args.swim_s)
            clean = (set(figures['launcher_codes']) == {0} and set(figures['reported']) == {'0'}
                     and len(figures['reported']) == figures['processes'] and not figures['left']
                     and figures['slowest_s'] <= args.bound)
            bad += not clean
            slowest.append(figures['slowest_s'])
            print(f'round {run + 1}: {figures["processes"]} processes, slowest stop '
                  f'{figures["slowest_s"]:.2f} s ({figures["slowest"]}), '
                  f'launchers {figures["launcher_codes"]}, '
                  f'reported codes {sorted(set(figures["reported"]))}, left {figures["left"]}, '
                  f'load {os.getloadavg()[0]:.1f}{"" if clean else "  <-- NOT CLEAN"}',
                  flush=True)
            if not clean:  # what the launcher said, and the end of the slowest one's log
                logs = sorted(Path(tmp, f'r{run}').glob(f'g*/run_*/logs/{figures["slowest"]}.log'))
                tail = logs[-1].read_text(errors='replace').splitlines()[-40:] if logs else []
                print('    ' + '\n    '.join(figures['said'][-60:] + tail), flush=True)
    print(f'{args.runs} rounds of {args.graphs} graph(s): {args.runs - bad} clean; slowest stop '
          f'median {statistics.median(slowest):.2f} s, max {max(slowest):.2f} s '
          f'(bound {args.bound:g} s)')
    return 0 if bad == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
