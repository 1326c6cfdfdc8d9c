# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --sim --duration` counts the virtual fish's seconds, not the wall's."""

import time

from e2e_utils import start_graph
import pytest
from wirefish_bag.bagfile import read_bag
from wirefish_bringup.graph import entry

pytestmark = pytest.mark.ros

DURATION_S = 4.0
# Simulated time at most at half the wall's pace: 4 simulated seconds take at least 8 wall
# seconds, where a count of wall seconds would stop after 4 (a slower machine only adds).
SPEED = 0.5
NAMESPACE = '/e2e_timed_run'
# n samples of the 50 Hz ground truth span n - 1 periods (the 200 of a 4 s run, 3.98 s: seen
# when the recorder stopped at once), and the window's start may fall between two samples.
TRUTH_PERIOD_S = 1.0 / entry('fish_sim').rates_hz['sim/ground_truth']


def test_a_timed_run_lasts_its_duration_of_simulated_time(e2e_domain_id, tmp_path):
    graph = start_graph(e2e_domain_id, tmp_path, '--speed', f'{SPEED:g}',
                        '--duration', f'{DURATION_S:g}', namespace=NAMESPACE)
    started = time.monotonic()
    output = graph.launcher.communicate(timeout=120)[0]
    wall_s = time.monotonic() - started
    truth = read_bag(next(tmp_path.glob('run_*/bag')),
                     [f'{NAMESPACE}/sim/ground_truth']).messages[f'{NAMESPACE}/sim/ground_truth']
    stamps = [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for _, m in truth]
    print(f'--speed {SPEED:g} --duration {DURATION_S:g}: {wall_s:.1f} wall s from the '
          f'recording line to the exit; the bag holds {max(stamps) - min(stamps):.2f} s of '
          'simulated ground truth')
    assert graph.launcher.returncode == 0, output
    assert 'recording, simulated seconds' in output  # its progress counts them
    assert wall_s >= DURATION_S / SPEED - 0.5, output
    assert max(stamps) - min(stamps) >= DURATION_S - 2 * TRUTH_PERIOD_S
