# SPDX-License-Identifier: Apache-2.0
"""`wirefish up --speed`: the virtual fish's pace, refused where the wall clock is the claim."""

import argparse
import subprocess
import sys

import pytest
from wirefish_launcher.verb.up import on_simulated_time_road, speed_option


def test_a_speed_is_a_factor_on_real_time_or_max():
    assert speed_option('1') == '1' and speed_option(' MAX ') == 'max'
    for bad in ('0', '-2', 'fast', 'nan'):
        with pytest.raises(argparse.ArgumentTypeError, match='--speed'):
            speed_option(bad)


def test_only_the_virtual_fish_on_one_host_runs_on_simulated_time():
    def road(**options) -> bool:
        values = {'port': None, 'fish': None, 'role': 'all', 'radio': None, **options}
        return on_simulated_time_road(argparse.Namespace(**values))

    assert road() and road(fish='sim')
    assert not road(port='/dev/ttyUSB0') and not road(fish='qemu')
    assert not road(role='fish') and not road(role='shore')
    assert not road(radio='bluetooth')  # a radio's timing is the wall clock's


def test_a_speed_for_a_real_fish_is_refused_with_its_reason(tmp_path):
    result = subprocess.run(
        [sys.executable, '-m', 'wirefish_cli.cli', 'up', '--port', '/dev/ttyUSB9', '--speed',
         '2', '--no-status', '--out', str(tmp_path)],
        capture_output=True, text=True, timeout=60)
    assert result.returncode == 2, result.stderr
    assert 'run on the wall clock' in result.stderr and '--port' in result.stderr
    assert not list(tmp_path.iterdir())  # nothing started, nothing written
