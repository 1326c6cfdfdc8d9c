# SPDX-License-Identifier: Apache-2.0
"""The checks of a serial port, a parameter file and a bag directory (pure: files, no ROS)."""

import os
from pathlib import Path
import pty

import pytest
from wirefish_common.input_checks import (bag_directory_problem, params_file_problem,
                                          serial_port_problem)

# The graph's default parameter file as the workspace ships it (wirefish_bringup/config).
DEFAULT_PARAMS = (Path(__file__).resolve().parents[2] / 'wirefish_bringup' / 'config'
                  / 'wirefish.yaml')


@pytest.mark.parametrize('port, problem', [
    ('/etc/passwd',
     '--port /etc/passwd is a regular file, not a serial device (e.g. /dev/ttyUSB0)'),
    ('/etc', '--port /etc is a directory, not a serial device (e.g. /dev/ttyUSB0)'),
    ('/dev/null', '--port /dev/null is a mem device, not a serial port '
                  '(a tty such as /dev/ttyUSB0 or /dev/ttyACM0)'),
    ('/dev/ttyUSB_not_plugged_in', None),
])
def test_a_port_that_is_no_serial_device_is_refused(port, problem):
    assert serial_port_problem(port) == problem


def test_a_pseudo_terminal_is_a_serial_device():
    master, slave = pty.openpty()
    try:
        assert serial_port_problem(os.ttyname(slave)) is None
    finally:
        os.close(master)
        os.close(slave)


def test_the_installed_parameter_file_is_accepted():
    assert params_file_problem(DEFAULT_PARAMS) is None


@pytest.mark.parametrize('content, problem', [
    (None, 'does not exist'),
    ('a: [1, 2\n', 'is not valid YAML at line 2'),
    ('- 1\n- 2\n', 'is not a ROS parameter file'),
    ('/**:\n  frequency_hz: 1.0\n', ': /** is not a ROS parameter file'),
    ('', 'is not a ROS parameter file'),
])
def test_a_parameter_file_the_nodes_cannot_read_is_refused(tmp_path, content, problem):
    path = tmp_path / 'params.yaml'
    if content is not None:
        path.write_text(content)
    assert problem in params_file_problem(path)


@pytest.mark.parametrize('make, problem', [
    (lambda p: None, 'does not exist'),
    (lambda p: p.write_text('x'), 'is not a directory'),
    (lambda p: p.mkdir(), 'holds no .mcap file'),
    (lambda p: (p.mkdir(), (p / 'metadata.yaml').write_text('{}')), 'holds no .mcap file'),
])
def test_what_is_no_bag_is_said_plainly(tmp_path, make, problem):
    bag = tmp_path / 'bag'
    make(bag)
    assert problem in bag_directory_problem(bag)


def test_a_bag_left_by_a_killed_recorder_is_a_bag(tmp_path):
    (tmp_path / 'bag_0.mcap').write_bytes(b'\x89MCAP0\r\n')
    assert bag_directory_problem(tmp_path) is None
