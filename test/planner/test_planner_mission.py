# SPDX-License-Identifier: Apache-2.0
"""
The square mission through `wirefish mission` on the virtual fish: recorded, reported, plotted.

A module of its own (not test_planner_graph.py), so that under `make test` (xdist, one file a
worker) it swims on one worker while the drive swims on the other: each needs about a minute
of swimming, and together in one file they were the longest tail of the suite.
"""

import re
import subprocess
import sys

import pytest


@pytest.mark.ros
def test_square_mission_is_recorded_and_reported(planner_graph, tmp_path):
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
