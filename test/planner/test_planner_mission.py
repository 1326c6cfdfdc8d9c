# SPDX-License-Identifier: Apache-2.0
"""
The square mission through `wirefish mission` on the virtual fish: recorded, reported, plotted.

A graph of its own (test_planner_graph.py's drive is another experiment), on the lockstep
clock at ``--speed max``: the mission sends each command at its step of the graph's clock and
holds the clock until it has, and the planner holds it at its ticks, so its loop, and the CPG's
start it calls at the first leg (a tick answers once the start is), keep simulated time however
fast the graph runs and however long the machine starves the mission.
"""

import os
import re
import signal
import subprocess
import sys
import threading
import time

import pytest

GRAPH_SPEED = 'max'
# Each leg's mean speed, at least this share of its setpoint (the report's leg lines).
LEG_SPEED_SHARE = 0.85
# The mission stopped (SIGSTOP) in its second leg for this long (wall s): a starved process.
# Below fish_sim's grace for a silent holder (lockstep.DEFAULT_GRACE_S, 5 s); at --speed max a
# graph that ran on meanwhile would leave the planner seconds of simulated time without cmd_vel.
STOPPED_S = 3.0
MISSION_TIMEOUT_S = 180.0


def _run_stopped_in(args: list[str], env: dict[str, str], leg: bytes,
                    stdout_path) -> tuple[subprocess.CompletedProcess, bool]:
    """Run ``args``; stop it for STOPPED_S once its stderr shows ``leg``; say if it was."""
    stderr, stopped = bytearray(), []
    with open(stdout_path, 'wb') as stdout:
        proc = subprocess.Popen(args, env=env, stdout=stdout, stderr=subprocess.PIPE)

    def read_stderr() -> None:
        for chunk in iter(lambda: os.read(proc.stderr.fileno(), 4096), b''):
            stderr.extend(chunk)
            if not stopped and leg in stderr:
                os.kill(proc.pid, signal.SIGSTOP)
                time.sleep(STOPPED_S)
                os.kill(proc.pid, signal.SIGCONT)
                stopped.append(leg)

    reader = threading.Thread(target=read_stderr)
    reader.start()
    try:
        proc.wait(timeout=MISSION_TIMEOUT_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        reader.join(timeout=30.0)
        proc.stderr.close()
    return subprocess.CompletedProcess(args, proc.returncode, stdout_path.read_text(),
                                       stderr.decode(errors='replace')), bool(stopped)


@pytest.mark.ros
def test_square_mission_is_recorded_and_reported_though_stopped_in_a_leg(
        simulated_planner_graph, tmp_path):
    planner_graph = simulated_planner_graph
    out = tmp_path / 'square'
    proc, stopped = _run_stopped_in(
        [sys.executable, '-m', 'wirefish_cli.cli', 'mission', 'square', '--namespace',
         planner_graph.namespace, '-o', str(out)], planner_graph.env, b'| leg 2/8',
        tmp_path / 'stdout')
    print(proc.stdout, proc.stderr)
    assert stopped, 'the mission never showed its second leg'
    assert proc.returncode == 0
    closure = re.search(r'closure error ([0-9.]+) m over a ([0-9.]+) m path', proc.stdout)
    assert closure is not None
    png = out / 'square.png'
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert (out / 'bag' / 'metadata.yaml').exists()
    assert 'turn gain' in proc.stdout  # identified from the recorded planner_state, or why not
    assert 'the fish comes to rest first' in proc.stdout
    assert re.search(r'mission square: \d+/\d+, about .* left \| leg 1/8', proc.stderr)
    assert '[wirefish_recorder]' not in proc.stdout + proc.stderr  # no line per recorded topic
    # Four 1.6 m sides and four quarter turns of radius 0.67 m: about 10.6 m of path.
    assert 9.0 < float(closure[2]) < 12.0
    # Every leg swum, the first too: the fish starts at the first leg's time of the graph's
    # clock, however long the CPG's start took in wall time (at 1: 0.184-0.203 m/s a leg).
    legs = re.findall(r'leg +(\d+): speed ([0-9.]+) -> ([0-9.]+) m/s', proc.stdout)
    assert len(legs) == 8
    slow = [(int(n), float(got)) for n, wanted, got in legs
            if float(got) < LEG_SPEED_SHARE * float(wanted)]
    assert not slow, f'legs swum below {LEG_SPEED_SHARE:.0%} of their speed: {slow}'
