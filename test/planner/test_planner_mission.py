# SPDX-License-Identifier: Apache-2.0
"""
The square mission through `wirefish mission` on the virtual fish: recorded, reported, plotted.

A graph of its own (test_planner_graph.py's drive is another experiment), on the lockstep
clock at ``--speed max``: the mission keeps the fish's time (its ground truth's stamps) and the
planner holds the clock at its ticks, so its loop, and the CPG's start it calls at the first
leg (a tick answers once the start is), keep simulated time however fast the graph runs.
"""

import re
import subprocess
import sys

import pytest

GRAPH_SPEED = 'max'
# Each leg's mean speed, at least this share of its setpoint (the report's leg lines).
LEG_SPEED_SHARE = 0.85


@pytest.mark.ros
def test_square_mission_is_recorded_and_reported(simulated_planner_graph, tmp_path):
    planner_graph = simulated_planner_graph
    out = tmp_path / 'square'
    proc = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'mission', 'square', '--namespace',
         planner_graph.namespace, '-o', str(out)],
        env=planner_graph.env, capture_output=True, text=True, timeout=180)
    print(proc.stdout, proc.stderr)
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
