# SPDX-License-Identifier: Apache-2.0
"""calibrate_drag's command: progress of the virtual fish's runs, and Ctrl-C in one line."""

import pytest
from wirefish_analysis import calibrate_drag


def test_the_virtual_fish_runs_show_their_progress(capsys):
    assert calibrate_drag.main([]) == 0
    err = capsys.readouterr().err
    assert 'calibrate_drag: 1/3, about' in err
    assert 'calibrate_drag: 3/3, done in' in err


def test_ctrl_c_is_one_line_and_exit_130(capsys, monkeypatch: pytest.MonkeyPatch):
    def interrupted(*_args, **_kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(calibrate_drag, 'virtual_fish_speeds', interrupted)
    assert calibrate_drag.main([]) == 130
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1] == 'calibrate_drag: interrupted (Ctrl-C)'
    assert 'Traceback' not in err
