"""
The `wirefish` command: run, retune, record and inspect the fish without ros2cli.

Every subcommand is also reachable on a full install (`ros2 run wirefish_bringup wirefish ...`),
beside the standard tools it stands in for on pip-only machines.
"""

import argparse
import importlib
import math
import os
import sys

# subcommand -> (module, one-line help); modules are imported only when their command runs,
# so `wirefish --help` stays fast and a plotting dependency never slows `wirefish up`.
SUBCOMMANDS = {
    'up': ('wirefish_bringup.launcher', 'start the whole graph (virtual fish by default)'),
    'qemu': ('wirefish_bringup.qemu_board',
             "the firmware's ARM build on an emulated board (QEMU), its link on a pty"),
    'record': ('wirefish_bringup.record', 'record the graph into a rosbag2 (MCAP) bag'),
    'retune': ('wirefish_bringup.retune', 'fit the CPG to a body wave (retune_gait action)'),
    'hand-back': ('wirefish_bringup.hand_back',
                  "give the gait back to the planner after a retune's manual override"),
    'gaits': ('wirefish_bringup.gaits', 'build, list and plot the gait library'),
    'drive': ('wirefish_bringup.drive', 'drive the fish from the keyboard (cmd_vel teleop)'),
    'mission': ('wirefish_bringup.mission',
                'timed cmd_vel legs, recorded, with a trajectory report'),
    'report': ('wirefish_bringup.report', 'plots and a summary table from a recorded bag'),
    'bag': ('wirefish_bringup.bag_command', 'reindex a killed recording; bag info'),
    'play': ('wirefish_bringup.play_command', "publish a bag's messages again (ros2 bag play)"),
    'topic': ('wirefish_bringup.topic_command',
              'list topics, echo one, show its rate (ros2 topic)'),
    'param': ('wirefish_bringup.param_command',
              "list, get and set a node's parameters (ros2 param)"),
    'compose': ('wirefish_bringup.compose', "one fish's ROS nodes in a single process"),
    'twohost': ('wirefish_bringup.twohost',
                'fish and shore on two network-namespace hosts over DDS (root)'),
}
# Other packages add subcommands through this entry-point group ('name = module'), as ros2cli
# extensions do: wirefish_analysis adds `sweep`, and bringup needs no import of them.
PLUGIN_GROUP = 'wirefish.commands'
INTERRUPTED = 130  # the exit code of a command stopped by Ctrl-C (128 + SIGINT)


def subcommands() -> dict[str, tuple[str, str]]:
    """Return every subcommand: this package's and those other installed packages add."""
    from importlib.metadata import entry_points

    found = dict(SUBCOMMANDS)
    for point in entry_points(group=PLUGIN_GROUP):
        found.setdefault(point.name, (point.value, f'(from {point.value.split(".")[0]})'))
    return found


def duration_s(text: str) -> float:
    """Return a --duration option as seconds: finite and > 0 (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a number of seconds: {text!r}') from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f'must be a finite number of seconds > 0, got {text}')
    return value


_OWN = {module for module, _ in SUBCOMMANDS.values()}


def _first_line(doc: str | None) -> str:
    return (doc or '').strip().splitlines()[0] if (doc or '').strip() else ''


def build_parser(argv: list[str]) -> argparse.ArgumentParser:
    """Return the parser; only the chosen subcommand's module is imported."""
    parser = argparse.ArgumentParser(prog='wirefish', description=__doc__.strip().splitlines()[0])
    commands = parser.add_subparsers(dest='command', required=True, metavar='COMMAND')
    for name, (module_name, help_text) in subcommands().items():
        if name in argv:
            module = importlib.import_module(module_name)
            help_text = help_text if module_name in _OWN else _first_line(module.__doc__)
        sub = commands.add_parser(name, help=help_text, description=help_text)
        if name in argv:
            module.add_arguments(sub)
            sub.set_defaults(run=module.run)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `wirefish` executable."""
    argv = sys.argv[1:] if argv is None else argv
    # Arguments after --ros-args belong to ROS, not to us (ros2 run passes them through).
    if '--ros-args' in argv:
        argv = argv[:argv.index('--ros-args')]
    args = build_parser(argv).parse_args(argv)
    try:
        return args.run(args)
    except KeyboardInterrupt:
        # A command without its own SIGINT handling (a sweep, a fit): one line, no traceback.
        from wirefish_common.progress import end_line
        end_line()
        print(f'wirefish {args.command}: interrupted (Ctrl-C)', file=sys.stderr)
        return INTERRUPTED
    except BrokenPipeError:
        # Piped into a reader that left (`wirefish topic echo ... | head`): end quietly, as
        # the shell's own tools do; stdout goes nowhere so the exit flush cannot fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


if __name__ == '__main__':
    sys.exit(main())
