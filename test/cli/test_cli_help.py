# SPDX-License-Identifier: Apache-2.0
"""Every `wirefish` subcommand's --help describes every option and cites no issue (pure)."""

import argparse
import re

import pytest
from wirefish_cli import api, cli

# What a user's help text must not say: a tracker's number, a Python tuple or None shown as is.
_ISSUE = re.compile(r'\bissues?\s+\d+', re.IGNORECASE)
_PYTHON_REPR = re.compile(r"\('[^']*',\)|\(\)|\bNone\b")


def _parsers(parser: argparse.ArgumentParser, path: str):
    """Yield (command path, parser) for ``parser`` and every sub-parser below it."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, f'{path} {name}')


def command_parsers() -> list[tuple[str, argparse.ArgumentParser]]:
    """Return every (command path, parser) of `wirefish`, each subcommand's module imported."""
    found = [('wirefish', cli.build_parser([]))]
    for name in api.verbs():
        parser = cli.build_parser([name])
        found += [item for item in _parsers(parser, 'wirefish') if item[0].split()[1:2] == [name]]
    return found


PARSERS = command_parsers()


def undescribed_options(parser: argparse.ArgumentParser) -> list[str]:
    """Return the options and positionals of ``parser`` that have no help text."""
    return [action.option_strings[0] if action.option_strings else action.dest
            for action in parser._actions
            if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction))
            and not (action.help or '').strip() and action.help != argparse.SUPPRESS]


def test_every_subcommand_is_found():
    assert {'wirefish up', 'wirefish drive', 'wirefish gaits build',
            'wirefish bag reindex'} <= {path for path, _ in PARSERS}


@pytest.mark.parametrize('path, parser', PARSERS, ids=[p for p, _ in PARSERS])
def test_every_option_has_a_description(path, parser):
    assert not undescribed_options(parser), f'{path}: no help for {undescribed_options(parser)}'


@pytest.mark.parametrize('path, parser', PARSERS, ids=[p for p, _ in PARSERS])
def test_the_help_cites_no_issue_and_shows_no_python(path, parser):
    text = parser.format_help()
    assert not _ISSUE.search(text) and not _PYTHON_REPR.search(text), text


@pytest.mark.parametrize('path, parser', PARSERS, ids=[p for p, _ in PARSERS])
def test_the_command_has_a_description(path, parser):
    assert (parser.description or '').strip(), f'{path} has no description'


def test_an_undescribed_option_is_found():
    parser = argparse.ArgumentParser()
    parser.add_argument('--described', help='something')
    parser.add_argument('--bare')
    assert undescribed_options(parser) == ['--bare']


def test_every_verb_of_the_workspace_is_registered_by_its_package():
    assert set(api.verbs()) == {
        'up', 'qemu', 'compose', 'twohost', 'record', 'bag', 'play', 'report', 'retune',
        'hand-back', 'gaits', 'drive', 'mission', 'topic', 'param', 'sweep', 'calibrate',
        'identify-geometry', 'view'}
