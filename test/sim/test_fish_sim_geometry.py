# SPDX-License-Identifier: Apache-2.0
"""fish_sim swims with the geometry of the graph's params file, and refuses an invalid one."""

from pathlib import Path
import subprocess

from ament_index_python.packages import get_package_prefix
import pytest
import yaml

BIN = Path(get_package_prefix('wirefish_sim')) / 'lib' / 'wirefish_sim'
pytestmark = pytest.mark.ros


def _geometry_line(proc: subprocess.Popen) -> str:
    for line in proc.stdout:
        if line.startswith('fish_sim: geometry'):
            return line
    raise AssertionError('fish_sim printed no geometry line')


def test_fish_sim_takes_the_geometry_of_the_params_file(spawn, tmp_path):
    params = tmp_path / 'params.yaml'  # the graph's one /** block, as in config/wirefish.yaml
    params.write_text(yaml.safe_dump({'/**': {'ros__parameters': {'l1': 0.09,
                                                                  'wetted_area': 0.2}}}))
    proc = spawn([str(BIN / 'fish_sim'), '--link', str(tmp_path / 'tty'), '--ros',
                  '--ros-args', '--params-file', str(params)])
    line = _geometry_line(proc)
    assert 'ROS parameters' in line and 'l1 0.09,' in line and 'wetted_area 0.2,' in line
    assert 'l2 0.1,' in line  # not in the file: FishGeometry's default


def test_fish_sim_without_ros_swims_with_the_defaults(spawn, tmp_path):
    proc = spawn([str(BIN / 'fish_sim'), '--link', str(tmp_path / 'tty')])
    line = _geometry_line(proc)
    assert '(defaults)' in line and 'l1 0.08,' in line


@pytest.mark.parametrize('value', ['-0.1', '0.0', '.nan'])
def test_an_invalid_geometry_ends_fish_sim_with_one_line_and_exit_1(spawn, tmp_path, value):
    proc = spawn([str(BIN / 'fish_sim'), '--link', str(tmp_path / 'tty'), '--ros',
                  '--ros-args', '-p', f'l1:={value}'])
    output, _ = proc.communicate(timeout=60.0)
    assert proc.returncode == 1, output
    assert 'l1' in output and 'Traceback' not in output, output
    assert not (tmp_path / 'tty').exists()  # refused before any device was opened
