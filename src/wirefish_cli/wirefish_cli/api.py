# SPDX-License-Identifier: Apache-2.0
"""
What the verbs of the `wirefish` command share: option types, exit codes, the verb registry.

A package adds verbs to `wirefish` through the ``wirefish.commands`` entry-point group
(``name = module``), as ros2cli's extensions do: the module has a docstring whose first line
is the verb's help, ``add_arguments(parser)`` and ``run(args) -> int``. The command imports
only the chosen verb's module, so `wirefish --help` stays fast, and a host has exactly the
verbs of the packages it installed (the fish no tuner's, no plotting's).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from importlib.metadata import entry_points
import math
import os
import sys

VERB_GROUP = 'wirefish.commands'
INTERRUPTED = 130  # the exit code of a command stopped by Ctrl-C (128 + SIGINT)
USAGE = 2  # the exit code of a command refused before it did anything (argparse's)


class UsageError(ValueError):
    """A verb's input that argparse could not judge (a namespace, a file): said, exit 2."""


def verbs() -> dict[str, str]:
    """Return every installed verb: its name and the module that implements it."""
    return {point.name: point.value for point in
            sorted(entry_points(group=VERB_GROUP), key=lambda point: point.name)}


def without_ros_args(argv: list[str]) -> list[str]:
    """Return a command line without ``--ros-args`` and what follows: those belong to ROS."""
    return argv[:argv.index('--ros-args')] if '--ros-args' in argv else argv


def duration_s(text: str) -> float:
    """Return a --duration option as seconds: finite and > 0 (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a number of seconds: {text!r}') from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f'must be a finite number of seconds > 0, got {text}')
    return value


def run_verb(run: Callable[[argparse.Namespace], int], args: argparse.Namespace,
             name: str) -> int:
    """Run a verb: a UsageError is one line and exit 2, Ctrl-C exit 130, a closed pipe quiet."""
    try:
        return run(args)
    except UsageError as error:
        print(f'{name}: {error}', file=sys.stderr)
        return USAGE
    except KeyboardInterrupt:
        # A command without its own SIGINT handling (a sweep, a fit): one line, no traceback.
        from wirefish_common.progress import end_line
        end_line()
        print(f'{name}: interrupted (Ctrl-C)', file=sys.stderr)
        return INTERRUPTED
    except BrokenPipeError:
        # Piped into a reader that left (`wirefish topic echo ... | head`): end quietly, as
        # the shell's own tools do; stdout goes nowhere so the exit flush cannot fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


def verb_main(add_arguments: Callable[[argparse.ArgumentParser], None],
              run: Callable[[argparse.Namespace], int], prog: str, description: str) -> int:
    """
    Run one verb as an executable of its own (a registry entry ``ros2 run`` starts).

    The arguments after ``--ros-args`` belong to ROS and are left out.
    """
    argv = without_ros_args(sys.argv[1:])
    parser = argparse.ArgumentParser(prog=prog, description=description)
    add_arguments(parser)
    return run_verb(run, parser.parse_args(argv), prog)
