# SPDX-License-Identifier: Apache-2.0
"""`wirefish hand-back` refuses a timeout it could not wait for, before it touches ROS."""

import argparse

import pytest
from wirefish_operator.verb.hand_back import add_arguments, WAIT_S


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog='wirefish hand-back')
    add_arguments(parser)
    return parser.parse_args(argv)


@pytest.mark.parametrize('timeout', ['nan', 'inf', '-1', '0', 'soon'])
def test_a_timeout_that_is_no_finite_positive_time_is_refused(timeout):
    with pytest.raises(SystemExit) as refused:
        _parse(['--timeout', timeout])
    assert refused.value.code == 2


def test_the_default_timeout_is_taken_without_the_option():
    assert _parse([]).timeout == WAIT_S
