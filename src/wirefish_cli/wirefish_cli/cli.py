# SPDX-License-Identifier: Apache-2.0
"""
The `wirefish` command: run, retune, record and inspect the fish without ros2cli.

Every verb is also reachable on a full install (`ros2 run wirefish_cli wirefish ...`), beside
the standard tools it stands in for on pip-only machines. The verbs come from the installed
packages (``wirefish_cli.api.verbs``): a fish computer has `up`, a shore computer the rest.
"""

import argparse
import ast
import difflib
import importlib
import importlib.util
import os
from pathlib import Path
import sys

from wirefish_bringup.dds_profile import with_profile
from wirefish_cli.api import run_verb, verbs, without_ros_args


def _first_line(doc: str | None) -> str:
    """Return a docstring's first line without its leading `wirefish VERB ...`: name."""
    line = (doc or '').strip().splitlines()[0] if (doc or '').strip() else ''
    if line.startswith('`wirefish') and '`: ' in line:
        line = line.split('`: ', 1)[1]
    return line


def _help_of(module_name: str) -> str:
    """Return a verb's one-line help, the first line of its module's docstring, unimported."""
    spec = importlib.util.find_spec(module_name)
    if spec is None or spec.origin is None:
        return f'(not importable: {module_name})'
    return _first_line(ast.get_docstring(ast.parse(Path(spec.origin).read_text())))


def build_parser(argv: list[str]) -> argparse.ArgumentParser:
    """Return the parser; the chosen verb's module is imported, the others' docstrings read."""
    parser = argparse.ArgumentParser(prog='wirefish', description=__doc__.strip().splitlines()[0])
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')
    chosen = next((word for word in argv if not word.startswith('-')), None)
    for name, module_name in verbs().items():
        if name == chosen:
            module = importlib.import_module(module_name)
            help_text = _first_line(module.__doc__)
            sub = commands.add_parser(name, help=help_text, description=help_text)
            module.add_arguments(sub)
            sub.set_defaults(run=module.run)
            parser.set_defaults(verb_parser=sub)
        else:
            commands.add_parser(name, help=_help_of(module_name))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `wirefish` executable."""
    # ros2 run passes the ROS arguments through: they are not ours.
    argv = without_ros_args(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    args, extra = parser.parse_known_args(argv)
    if extra:  # the verb's own usage and the option it has closest to what was typed
        unknown_option(getattr(args, 'verb_parser', parser), extra)
    # The command's own participant (a recorder, a mission, a probe) takes the Fast DDS profile
    # `wirefish up` gives the graph's nodes, whatever the shell set after tools/activate.sh:
    # under LOCALHOST rmw's own loopback transport kept the kernel's default socket buffer,
    # and a `wirefish record` beside two loaded graphs lost 8-9 of each 100 Hz stream.
    os.environ.update(with_profile(os.environ))
    return run_verb(args.run, args, f'wirefish {args.command}')


def unknown_option(parser: argparse.ArgumentParser, extra: list[str]) -> None:
    """Exit through ``parser``'s error: its usage, the words it does not know, the closest."""
    known = [option for action in parser._actions for option in action.option_strings]
    close = difflib.get_close_matches(extra[0], known, n=1) if extra[0].startswith('-') else []
    hint = f' (did you mean {close[0]}?)' if close else ''
    parser.error(f'unrecognized arguments: {" ".join(extra)}{hint}')


if __name__ == '__main__':
    sys.exit(main())
