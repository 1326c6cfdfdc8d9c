#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""
The virtual fish's speed over the radio road, run after run, in gait and in stream mode.

    tools/wfenv python tools/probes/radio_speed_spread.py --runs 2

Each run drives the whole graph three times with test/support/radio_run's 60 s of cmd_vel: the
wired preset in gait mode, the wired preset in stream mode, and rf433 in its road's mode
(gait). A line per drive: the ground truth's mean speed over 5-60 s and per command segment. The
radio road runs on the wall clock: in stream mode the tail follows the host's 100 Hz stream as it
arrives, in gait mode the fish integrates eq 1 itself, so compare each mode's spread across
runs; this is why test/sim/test_rf433_virtual_fish.py takes its reference in gait mode.
"""

import argparse
from pathlib import Path
import sys
import tempfile

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'test'))
from radio_run import drive, DRIVE_S, SCHEDULE  # noqa: E402, I101

DRIVES = (('wired', 'gait'), ('wired', 'stream'), ('rf433', None))


def main() -> None:
    """Drive the three drives ``--runs`` times; print each drive's speeds."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--runs', type=int, default=1, help='rounds of the three drives')
    args = parser.parse_args()
    if args.runs < 1:
        parser.error('--runs must be at least 1')
    ends = [start for start, *_ in SCHEDULE[1:]] + [DRIVE_S]
    segments = [(start + 5.0, end) for (start, *_), end in zip(SCHEDULE, ends)]
    with tempfile.TemporaryDirectory(prefix='radio_speed_') as out:
        for run in range(args.runs):
            for preset, mode in DRIVES:
                directory = Path(out, f'{run}_{preset}_{mode}')
                directory.mkdir()
                record = drive(directory, preset, drive_mode=mode)
                parts = ' '.join(f'{record.mean_speed(a, b):.4f}' for a, b in segments)
                print(f'run {run + 1} {preset} {mode or "road (gait)"}: 5-60 s '
                      f'{record.mean_speed(5.0, DRIVE_S):.4f} m/s; segments {parts}', flush=True)


if __name__ == '__main__':
    main()
