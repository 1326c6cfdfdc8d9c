# SPDX-License-Identifier: Apache-2.0
"""
`wirefish sweep`: model and virtual-fish swimming speed over the paper's grid (Figs 9-11).

The grid, the model and the virtual fish are ``wirefish_analysis.sweep``'s; this verb runs
them with a progress bar, prints the table and writes the figures and sweep.csv.
"""

import argparse
from pathlib import Path

from wirefish_analysis.sweep import run_sweep, sweep_size, table, write_outputs
from wirefish_common.progress import Progress


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of `wirefish sweep`."""
    parser.add_argument('-o', '--out', type=Path, default=Path('out', 'sweep'),
                        help='where the PNGs and sweep.csv go')
    parser.add_argument('--model-only', action='store_true',
                        help='skip the virtual fish (eq 18 only, a second instead of ten)')


def run(args: argparse.Namespace) -> int:
    """Run `wirefish sweep`; print the table and the files written."""
    label = 'sweep (eq 18)' if args.model_only else 'sweep (eq 18 and the virtual fish)'
    grid, line = run_sweep(with_fish=not args.model_only,
                           progress=Progress(label, sweep_size()))
    print(table(grid, line))
    for path in write_outputs(grid, line, args.out):
        print(f'wrote {path}')
    return 0
