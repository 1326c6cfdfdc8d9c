# SPDX-License-Identifier: Apache-2.0
"""
`wirefish report BAG`: plots and a summary table from a recorded run.

The figures and the table are ``wirefish_bag.report``'s; this verb checks the bag, writes
them beside it and prints the table.
"""

import argparse
from pathlib import Path
import sys

from wirefish_bag.report import write_report


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish report`."""
    parser.add_argument('bag', type=Path, help='rosbag2 directory (wirefish record / up)')
    parser.add_argument('-o', '--output', type=Path, default=None,
                        help='where the PNGs and summary go (default: <bag>_report)')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish report`; return the process exit code."""
    from wirefish_common.input_checks import bag_directory_problem

    problem = bag_directory_problem(args.bag)
    if problem is not None:
        print(f'wirefish report: {problem}', file=sys.stderr)
        return 2
    if not (args.bag / 'metadata.yaml').is_file():
        print(f'wirefish report: {args.bag} has no metadata.yaml: its recorder was killed? '
              f'`wirefish bag reindex {args.bag}` repairs it', file=sys.stderr)
        return 2
    out_dir = args.output or args.bag.with_name(args.bag.name + '_report')
    stats = write_report(args.bag, out_dir)
    print((out_dir / 'summary.txt').read_text(), end='')
    print(f'PNGs in {out_dir}: {", ".join(sorted(p.name for p in out_dir.glob("*.png")))}')
    return 0 if stats else 1
