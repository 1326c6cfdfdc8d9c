# SPDX-License-Identifier: Apache-2.0
"""`wirefish calibrate`: its options, the values `set` keeps, the table `show` prints."""

import argparse

import pytest
from wirefish_operator.verb.calibrate import add_arguments, Cal, merged, table

CURRENT = Cal(1, 2, -1, 1550.0, 600.0, 500.0, 2500.0)


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog='wirefish calibrate')
    add_arguments(parser)
    return parser.parse_args(argv)


@pytest.mark.parametrize('argv', [['set', '3'], ['set', '1', '--direction', '0'],
                                  ['set', '1', '--neutral-us', 'nan'], ['factory', 'x'],
                                  ['sweep', '2', '--amplitude', 'inf'], []])
def test_a_bad_command_line_is_refused_before_ros(argv):
    with pytest.raises(SystemExit) as refused:
        _parse(argv)
    assert refused.value.code == 2


def test_set_takes_its_servo_values_and_save():
    args = _parse(['set', '2', '--neutral-us', '1490', '--direction', '-1', '--save'])
    assert (args.servo, args.neutral_us, args.us_per_rad, args.direction, args.save) == (
        2, 1490.0, None, -1, True)


def test_set_keeps_the_current_value_of_each_option_not_given():
    assert merged(CURRENT, None, 610.0, None) == (-1, 1550.0, 610.0)
    assert merged(CURRENT, None, None, None) == (-1, 1550.0, 600.0)


def test_the_table_names_each_servo_s_source_and_values():
    lines = table([CURRENT, Cal(2, 0, 1, 1500.0, 636.62, 500.0, 2500.0)]).splitlines()
    assert lines[0].split() == ['servo', 'source', 'neutral_us', 'us_per_rad', 'direction',
                                'min_us', 'max_us']
    assert lines[1].split() == ['1', 'LIVE', '1550.0', '600.00', '-1', '500.0', '2500.0']
    assert lines[2].split()[:2] == ['2', 'DEFAULTS']


def test_sweep_defaults_to_a_slow_small_sweep():
    args = _parse(['sweep', '1'])
    assert (args.amplitude, args.period) == (0.3, 4.0)
