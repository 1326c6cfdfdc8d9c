# SPDX-License-Identifier: Apache-2.0
"""The launcher gives each virtual fish a calibration file under the run's directory."""

from pathlib import Path

from wirefish_bringup.fleet import fleet_graph
from wirefish_bringup.graph import fish_graph
from wirefish_launcher.verb.up import with_calibration_files

LOGS = Path('/run/x/logs')


def _fish_sim(specs):
    (spec,) = [s for s in specs if s.executable == 'fish_sim']
    return spec


def test_the_virtual_fish_gets_one_calibration_file_in_the_run_s_logs():
    specs = with_calibration_files(fish_graph('/wirefish', sim=True), LOGS)
    arguments = _fish_sim(specs).arguments
    at = arguments.index('--calibration')
    assert Path(arguments[at + 1]).parent == LOGS
    assert arguments.count('--calibration') == 1


def test_a_fleet_s_fish_sim_gets_one_file_per_fish():
    specs = with_calibration_files(fleet_graph('/wirefish', 3), LOGS)
    arguments = _fish_sim(specs).arguments
    files = [arguments[i + 1] for i, a in enumerate(arguments) if a == '--calibration']
    assert len(files) == len(set(files)) == 3


def test_a_real_fish_s_graph_is_left_as_it_is():
    specs = fish_graph('/wirefish', sim=False, port='/dev/ttyUSB0')
    assert with_calibration_files(specs, LOGS) == specs
