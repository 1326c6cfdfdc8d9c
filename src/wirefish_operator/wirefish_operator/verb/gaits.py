# SPDX-License-Identifier: Apache-2.0
"""
`wirefish gaits`: build, list and plot the gait library (the tuner's YAML file).

``build`` fits a grid of waves, tail-beat frequency x amplitude scale of a reference wave (the
paper's section 5.2 wave by default), on all cores (a process pool) with the tuner's default
fit settings and limits, and stores each successful fit in the library (merged under the
library's lock, so a running tuner keeps its gaits and sees the new ones). ``list`` prints the
library with the predicted speed of each gait (eq 18 on its locked steady state). ``plot``
draws that speed over the family's grid. No ROS graph is needed: they work on the file.
"""

from __future__ import annotations

import argparse
from concurrent.futures import as_completed, ProcessPoolExecutor
import os
from pathlib import Path
import signal
import sys

from wirefish_common.progress import Progress

DEFAULT_FREQUENCIES = '0.5,1.0,1.5,2.0,2.5'
DEFAULT_SCALES = '0.5,0.75,1.0,1.25,1.5'


def number_list(text: str) -> list[float]:
    """Return a comma-separated list of finite numbers > 0 (argparse type)."""
    try:
        values = [float(part) for part in text.split(',') if part.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a list of numbers: {text!r}') from None
    if not values or not all(0.0 < v < float('inf') for v in values):
        raise argparse.ArgumentTypeError(f'need finite numbers > 0, got {text!r}')
    return sorted(set(values))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare `wirefish gaits build | list | plot` and their options."""
    from wirefish_cpg.gait_library import default_library_path

    actions = parser.add_subparsers(dest='gaits_command', required=True, metavar='ACTION')
    helps = {'build': 'fit a frequency x amplitude-scale grid of gaits into the library',
             'list': 'the library as a table with eq 18 speeds',
             'plot': 'predicted speed over the family grid (PNG)'}
    build, listing, plot = (actions.add_parser(name, help=text, description=text)
                            for name, text in helps.items())
    for sub in (build, listing, plot):
        sub.add_argument('--library', type=Path, default=default_library_path(),
                         help='gait library file (default: %(default)s)')
        sub.add_argument('--c1', type=float, default=0.15, help='reference wave c1')
        sub.add_argument('--c2', type=float, default=1.0, help='reference wave c2 (1/m)')
        sub.add_argument('--k', type=float, default=8.0, help='reference wave k (rad/m)')
    build.add_argument('--frequencies', type=number_list, default=DEFAULT_FREQUENCIES,
                       help='tail-beat frequencies (Hz), comma-separated')
    build.add_argument('--scales', type=number_list, default=DEFAULT_SCALES,
                       help='amplitude scales of the reference envelope, comma-separated')
    build.add_argument('--seed', type=int, default=0, help='optimiser seed of every fit')
    build.add_argument('--workers', type=int, default=os.cpu_count() or 1,
                       help='processes (default: all cores)')
    plot.add_argument('--out', type=Path, default=Path('out', 'gaits_speed.png'),
                      help='PNG file (default: %(default)s)')


def fit_point(point: tuple[float, float, float, float, float, int]):
    """Fit one grid point (c1, c2, k, frequency, scale, seed); return (f, s, outcome)."""
    from wirefish_tuner.retune_core import retune, RetuneOrder, RetuneSettings

    c1, c2, k, frequency, scale, seed = point
    order = RetuneOrder(c1=c1 * scale, c2=c2 * scale, k=k, frequency_hz=frequency, seed=seed,
                        use_library=False)
    return frequency, scale, order, retune(order, RetuneSettings())


def predicted_speed(params) -> float:
    """Return eq 18's steady speed (m/s) of a gait's locked output, default geometry."""
    from wirefish_cpg.table1_gait import locked_speed_estimate
    from wirefish_kinematics.geometry import FishGeometry

    return float(locked_speed_estimate(params, FishGeometry()).speed)


def _ignore_interrupts() -> None:
    """Leave Ctrl-C to the parent (a worker's KeyboardInterrupt would print its traceback)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def build(args: argparse.Namespace) -> int:
    """Fit the grid on a process pool, store the successes, print the table."""
    from wirefish_cpg.gait_library import LibraryFile
    from wirefish_tuner.retune_core import gait_of, RetuneSettings

    points = [(args.c1, args.c2, args.k, f, s, args.seed)
              for f in args.frequencies for s in args.scales]
    rows, gaits = [], []
    progress = Progress('gaits build', len(points))
    pool = ProcessPoolExecutor(max_workers=max(1, args.workers), initializer=_ignore_interrupts)
    try:
        futures = [pool.submit(fit_point, point) for point in points]
        for future in as_completed(futures):
            frequency, scale, order, outcome = future.result()
            progress.step(text=f'f {frequency:g} Hz, scale {scale:g}: '
                          f'{"fitted" if outcome.success else "refused"}')
            rows.append((frequency, scale, outcome))
            if outcome.success:
                gaits.append(gait_of(order, outcome, RetuneSettings()))
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)  # the fits under way end by themselves
        raise
    pool.shutdown()
    if gaits:
        LibraryFile(args.library).add(gaits)
    print(grid_table(sorted(rows, key=lambda r: (r[0], r[1]))))
    print(f'{len(gaits)} of {len(points)} gaits stored in {args.library}')
    return 0 if gaits else 1


def grid_table(rows) -> str:
    """Return the build's rows (frequency, scale, outcome) as an aligned table."""
    lines = [f'{"f (Hz)":>7} {"scale":>6} {"RMSE th1/th2 (deg)":>19} {"loss (m*s)":>11} '
             f'{"speed (m/s)":>11}  outcome']
    for frequency, scale, outcome in rows:
        if outcome.success:
            rmse = f'{outcome.rmse_theta_deg[0]:.3f}/{outcome.rmse_theta_deg[1]:.3f}'
            lines.append(f'{frequency:7.3g} {scale:6.3g} {rmse:>19} {outcome.loss:11.4g} '
                         f'{predicted_speed(outcome.params):11.4f}  fitted')
        else:
            lines.append(f'{frequency:7.3g} {scale:6.3g} {"-":>19} {"-":>11} {"-":>11}  '
                         f'{outcome.message}')
    return '\n'.join(lines)


def reference_of(args: argparse.Namespace):
    """Return the reference wave of the options (frequency is free in a family)."""
    from wirefish_tuner.wave_loss import WaveSpec

    return WaveSpec(args.c1, args.c2, args.k, 1.0)


def missing_library_text(path: Path) -> str:
    """Return the line of a gait library file that does not exist."""
    return (f'no gait library at {path}: the file does not exist (`wirefish gaits build` or '
            'a `wirefish retune` makes it; --library names another)')


def list_gaits(args: argparse.Namespace) -> int:
    """Print every gait of the library, with its scale of the reference and eq 18 speed."""
    from wirefish_cpg.gait_family import scale_of
    from wirefish_cpg.gait_library import default_library_path, load_library

    if not args.library.exists():
        given = args.library != default_library_path()
        print(f'wirefish gaits: {missing_library_text(args.library)}', file=sys.stderr)
        return 1 if given else 0
    try:
        library = load_library(args.library)
    except (OSError, ValueError) as error:
        print(f'wirefish gaits: {error}', file=sys.stderr)
        return 1
    reference = reference_of(args)
    print(f'{"f (Hz)":>7} {"c1":>8} {"c2":>8} {"k":>7} {"scale":>6} '
          f'{"RMSE th1/th2 (deg)":>19} {"loss (m*s)":>11} {"speed (m/s)":>11}  fitted at')
    for gait in sorted(library.gaits, key=lambda g: (g.wave.frequency_hz, g.wave.c1)):
        w = gait.wave
        scale = scale_of(w, reference)
        rmse = f'{gait.rmse_theta_deg[0]:.3f}/{gait.rmse_theta_deg[1]:.3f}'
        print(f'{w.frequency_hz:7.3g} {w.c1:8.4g} {w.c2:8.4g} {w.k:7.4g} '
              f'{"-" if scale is None else f"{scale:.3g}":>6} {rmse:>19} {gait.loss:11.4g} '
              f'{predicted_speed(gait.params):11.4f}  {gait.fitted_at}')
    print(f'{len(library.gaits)} gaits in {args.library}')
    return 0


def plot(args: argparse.Namespace) -> int:
    """Draw eq 18's speed of the reference's family over (frequency, scale) to a PNG."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    from wirefish_cpg.gait_family import family_members
    from wirefish_cpg.gait_library import load_library
    from wirefish_tuner.retune_core import RetuneSettings

    if not args.library.exists():
        print(f'wirefish gaits: {missing_library_text(args.library)}', file=sys.stderr)
        return 1
    try:
        library = load_library(args.library)
    except (OSError, ValueError) as error:
        print(f'wirefish gaits: {error}', file=sys.stderr)
        return 1
    members = family_members(library, reference_of(args), RetuneSettings().geometry_fields())
    if not members:
        print('wirefish gaits: no gait of this reference wave in the library '
              '(wirefish gaits build)', file=sys.stderr)
        return 1
    figure, axes = plt.subplots(figsize=(6, 4.5))
    speeds = [predicted_speed(m.gait.params) for m in members]
    points = axes.scatter([m.frequency_hz for m in members], [m.scale for m in members],
                          c=speeds, s=220, cmap='viridis')
    figure.colorbar(points, label='predicted speed, eq 18 (m/s)')
    axes.set_xlabel('tail-beat frequency (Hz)')
    axes.set_ylabel(f'amplitude scale of (c1, c2) = ({args.c1:g}, {args.c2:g})')
    axes.set_title(f'gait family, k = {args.k:g} rad/m ({len(members)} gaits)')
    figure.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(args.out, dpi=120)
    print(f'wrote {args.out}')
    return 0


def run(args: argparse.Namespace) -> int:
    """Run `wirefish gaits ACTION`."""
    return {'build': build, 'list': list_gaits, 'plot': plot}[args.gaits_command](args)
