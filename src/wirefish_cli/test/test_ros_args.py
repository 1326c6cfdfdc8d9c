# SPDX-License-Identifier: Apache-2.0
"""`ros2 run` passes ROS arguments through: the commands drop them before parsing."""

import pytest
from wirefish_cli.api import without_ros_args
from wirefish_cli.cli import build_parser


@pytest.mark.parametrize('argv, ours', [
    (['up', '--sim'], ['up', '--sim']),
    (['up', '--sim', '--ros-args', '-r', '__ns:=/x'], ['up', '--sim']),
    (['--ros-args', '--params-file', 'p.yaml'], []),
    ([], []),
])
def test_everything_from_ros_args_on_is_left_out(argv, ours):
    assert without_ros_args(argv) == ours


def test_a_verb_parses_with_ros_arguments_behind_it():
    argv = without_ros_args(['up', '--sim', '--ros-args', '-r', '__node:=other'])
    args = build_parser(argv).parse_args(argv)
    assert args.command == 'up' and args.sim
