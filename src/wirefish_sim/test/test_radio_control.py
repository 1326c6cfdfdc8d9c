# SPDX-License-Identifier: Apache-2.0
"""The radio relay's control file: a cut is taken only once its line is complete."""

from wirefish_sim.radio_relay import read_control_cuts


def test_a_complete_line_is_a_cut_and_the_file_is_removed(tmp_path):
    control = tmp_path / 'radio-control'
    control.write_text('cut 10\n')
    assert read_control_cuts(control) == [10.0]
    assert not control.exists()


def test_a_file_just_created_is_left_until_its_line_is_written(tmp_path):
    control = tmp_path / 'radio-control'
    control.touch()  # what a writer's open() leaves before its write()
    assert read_control_cuts(control) == []
    assert control.exists()
    control.write_text('cut 2.5\n')
    assert read_control_cuts(control) == [2.5]


def test_a_line_still_being_written_is_left_for_the_next_look(tmp_path):
    control = tmp_path / 'radio-control'
    control.write_text('cut 1')
    assert read_control_cuts(control) == []
    assert control.read_text() == 'cut 1'


def test_a_bad_line_is_no_cut(tmp_path):
    control = tmp_path / 'radio-control'
    control.write_text('cut ten\ncut -3\ncut nan\n')
    assert read_control_cuts(control) == []
    assert not control.exists()
