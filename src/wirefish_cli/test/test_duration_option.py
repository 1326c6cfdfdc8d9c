# SPDX-License-Identifier: Apache-2.0
"""--duration: a finite number of seconds > 0, refused otherwise before anything starts."""

import argparse
import importlib.util
from pathlib import Path
import re

import pytest
from wirefish_cli import cli
from wirefish_cli.api import duration_s, verbs
from wirefish_cli.cli import main

BAD_DURATIONS = ['-1', '0', 'nan', 'inf', 'ten']


def _verbs_with_a_duration() -> list[str]:
    """Return the installed verbs whose module declares a --duration option (read, unimported)."""
    return [name for name, module in verbs().items()
            if "'--duration'" in Path(importlib.util.find_spec(module).origin).read_text()]


@pytest.mark.parametrize('text', BAD_DURATIONS)
def test_a_duration_that_is_not_a_positive_finite_number_is_refused(text):
    with pytest.raises(argparse.ArgumentTypeError, match=re.escape(text)):
        duration_s(text)


def test_a_positive_finite_duration_is_taken_as_seconds():
    assert [duration_s(text) for text in ('0.5', '10', '1e3')] == [0.5, 10.0, 1000.0]


def test_the_verbs_that_take_a_duration_are_found():
    assert {'up', 'record', 'twohost'} <= set(_verbs_with_a_duration())


@pytest.mark.parametrize('text', ['0', 'ten'])
@pytest.mark.parametrize('verb', _verbs_with_a_duration())
def test_a_verb_refuses_a_bad_duration_in_one_line_before_anything_starts(
        verb, text, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # where `up` and `record` would write their run and bag
    started = []  # a duration let through would run the verb: here it is only noted
    monkeypatch.setattr(cli, 'run_verb', lambda run, args, name: started.append(name) or 0)
    with pytest.raises(SystemExit) as exit_:
        main([verb, '--duration', text])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.splitlines()[-1].startswith(f'wirefish {verb}: error: argument --duration:'), err
    assert started == [] and list(tmp_path.iterdir()) == []  # nothing started or written
