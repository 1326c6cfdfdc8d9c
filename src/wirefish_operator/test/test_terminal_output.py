# SPDX-License-Identifier: Apache-2.0
"""What the operator's verbs write on a terminal, read as a terminal shows it."""

import argparse
from pathlib import Path

import pytest
from wirefish_operator.verb import mission
from wirefish_operator.verb.drive import screen_lines, state_line
from wirefish_operator.verb.retune import bar_redraw, progress_line


def shown(written: str) -> list[str]:
    """Return the lines a terminal shows after ``written`` (CR, ESC[K and LF only)."""
    lines, column = [''], 0
    i = 0
    while i < len(written):
        if written.startswith('\x1b[K', i):
            lines[-1] = lines[-1][:column]
            i += 3
            continue
        char = written[i]
        if char == '\r':
            column = 0
        elif char == '\n':
            lines.append('')
            column = 0
        else:
            line = lines[-1]
            lines[-1] = line[:column] + char + line[column + 1:]
            column += 1
        i += 1
    return lines


def test_the_retune_bar_leaves_no_tail_of_a_longer_line():
    long = progress_line(40, 0.0123, 100, 'about 12 s left')
    last = progress_line(100, 0.0120, 100, 'done in 9 s')
    assert shown(bar_redraw(long) + bar_redraw(last)) == [last]


def test_mission_summary_starts_on_a_line_of_its_own(monkeypatch, tmp_path, capsys):
    from wirefish_common.progress import Progress

    class Terminal:
        def __init__(self) -> None:
            self.text = ''

        def write(self, text: str) -> None:
            self.text += text

        def flush(self) -> None:
            pass

        def isatty(self) -> bool:
            return True

    terminal = Terminal()

    def drive(*_args):  # the legs' bar stops at 19 of 20 s, as a timer tick can
        Progress('mission square', 20, stream=terminal).step(19, 'coasting, recording')
        return 0.0, None, False, None

    monkeypatch.setattr(mission, '_drive', drive)
    monkeypatch.setattr(mission, '_report',
                        lambda *_args: terminal.write('closure error 0.5 m\n') or 0)
    args = argparse.Namespace(mission='square', namespace='/wirefish', output=tmp_path / 'm',
                              wait=1.0)
    assert mission.run(args) == 0
    assert shown(terminal.text)[-2] == 'closure error 0.5 m', shown(terminal.text)


def test_an_unknown_mission_names_the_shipped_ones():
    with pytest.raises(ValueError, match=r"no mission 'circle'.*shipped: square"):
        mission.mission_path('circle')
    assert mission.mission_path(__file__) == Path(__file__)


def test_the_drive_line_labels_its_numbers_and_shows_the_whole_reason_once():
    from types import SimpleNamespace

    reason = 'speed clamped: ' + 'x' * 300
    state = SimpleNamespace(mode='hold', predicted_speed=0.3, tail_beat_hz=2.0,
                            amplitude_scale=1.0, yaw_rate_target=0.0, yaw_rate_measured=0.01,
                            offset=0.012, heading_target=float('nan'), clamp_reason=reason,
                            note='')
    line = state_line(0.3, 0.0, state)
    assert 'amplitude x1.00' in line and 'offset +0.012 rad' in line
    first, said = screen_lines(line, '', 80)
    assert said == reason
    assert shown(first)[0] == f'  planner: {reason}'  # whole, above the status line
    assert len(shown(first)[1]) <= 79
    again, _ = screen_lines(line, said, 80)
    assert len(shown(again)) == 1  # said once, not at every redraw
