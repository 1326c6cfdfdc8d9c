# SPDX-License-Identifier: Apache-2.0
"""
Model and virtual-fish swimming speed over the paper's grid (Figs 9-11), for `wirefish sweep`.

The grid of section 5.4 (``wirefish_cpg.table1_gait.PAPER_GRID_*``): f = 1.0 ... 3.0 Hz in
steps of 0.2 at tail-tip half amplitudes {4, 4.5, 6.5, 8, 9} cm, plus 5 cm from 1 to 8 Hz
(Fig 11). At each point Table 1's amplitudes are scaled so the ideal-servo tail tip swings the
stated amplitude, and the network is locked at f. "model" is eq 18 on the commanded angles
(kinematics core); "virtual fish" is the steady mean surge speed of the simulated fish (servo
rate limit and lag, surge dynamics) driven by the same commands. The paper's stated points are
drawn beside them.
"""

from dataclasses import dataclass
from pathlib import Path
from typing import overload

import numpy as np
from wirefish_common.plotting import legend_beside
from wirefish_common.progress import Progress
from wirefish_cpg.table1_gait import PAPER_GRID_AMPLITUDES_M, PAPER_GRID_FREQUENCIES_HZ

FIG11_AMPLITUDE_M = 0.05
FIG11_FREQUENCIES_HZ = tuple(float(f) for f in np.arange(1.0, 8.01, 0.5))
# The paper's figures as stated in its text: (f Hz, tip amplitude m or None for Table 1, U m/s).
PAPER_POINTS: tuple[tuple[float, float | None, float], ...] = (
    (3.0, None, 0.39), (6.5, 0.05, 0.54), (1.0, 0.09, 0.33 * 1.0 * 0.53))


@dataclass(frozen=True)
class SweepPoint:
    """One grid point: model and virtual-fish steady speed (m/s) and swimming numbers."""

    frequency_hz: float
    tip_amplitude_m: float
    model_speed: float
    fish_speed: float | None
    body_length: float

    @overload
    def swimming_number(self, speed: float) -> float: ...

    @overload
    def swimming_number(self, speed: None) -> None: ...

    @overload
    def swimming_number(self, speed: float | None) -> float | None: ...

    def swimming_number(self, speed: float | None) -> float | None:
        """Return Sw = U / (f L) for ``speed``."""
        return None if speed is None else speed / (self.frequency_hz * self.body_length)


def sweep_point(frequency_hz: float, tip_amplitude_m: float, with_fish: bool) -> SweepPoint:
    """Compute one grid point with the default geometry."""
    from wirefish_analysis.fig11 import run_steady
    from wirefish_cpg.table1_gait import locked_speed_estimate, table1_at_tip_amplitude
    from wirefish_kinematics.geometry import FishGeometry

    geometry = FishGeometry()
    params = table1_at_tip_amplitude(tip_amplitude_m, frequency_hz, geometry)
    model = locked_speed_estimate(params, geometry).speed
    fish = run_steady(params, frequency_hz, geometry).speed if with_fish else None
    return SweepPoint(frequency_hz, tip_amplitude_m, float(model), fish, geometry.body_length)


# Grid points swum together as one school (fig11.run_steady_school): the physics is one
# vectorised evaluation per step for the whole school, and the progress is told per school.
SCHOOL_SIZE = 14


def run_sweep(with_fish: bool = True,
              progress: Progress | None = None) -> tuple[list[SweepPoint], list[SweepPoint]]:
    """
    Return (the Fig 9/10 grid, the Fig 11 line); ``progress`` is told after each point.

    The virtual fish of ``SCHOOL_SIZE`` points at a time swim as one school: each point's
    speed is the one its fish alone gives (``sweep_point``), a fraction of the time.
    """
    from wirefish_analysis.fig11 import run_steady_school
    from wirefish_cpg.table1_gait import locked_speed_estimate, table1_at_tip_amplitude
    from wirefish_kinematics.geometry import FishGeometry

    geometry = FishGeometry()
    wanted = [*((f, a) for a in PAPER_GRID_AMPLITUDES_M for f in PAPER_GRID_FREQUENCIES_HZ),
              *((f, FIG11_AMPLITUDE_M) for f in FIG11_FREQUENCIES_HZ)]
    points = []
    for first in range(0, len(wanted), SCHOOL_SIZE):
        school = wanted[first:first + SCHOOL_SIZE]
        gaits = [(table1_at_tip_amplitude(a, f, geometry), f) for f, a in school]
        fish = (run_steady_school(gaits, geometry) if with_fish else [None] * len(school))
        for (frequency, amplitude), (params, _), run in zip(school, gaits, fish):
            model = locked_speed_estimate(params, geometry).speed
            points.append(SweepPoint(frequency, amplitude, float(model),
                                     None if run is None else run.speed,
                                     geometry.body_length))
            if progress is not None:
                progress.step(text=f'{frequency:g} Hz, {amplitude * 100:g} cm')
    split = len(PAPER_GRID_AMPLITUDES_M) * len(PAPER_GRID_FREQUENCIES_HZ)
    return points[:split], points[split:]


def sweep_size() -> int:
    """Return how many points a sweep computes (the grid's, then the Fig 11 line's)."""
    return (len(PAPER_GRID_AMPLITUDES_M) * len(PAPER_GRID_FREQUENCIES_HZ)
            + len(FIG11_FREQUENCIES_HZ))


def write_outputs(grid: list[SweepPoint], line: list[SweepPoint], out: Path) -> list[Path]:
    """Write sweep.csv and the Fig 9/10/11-like PNGs; return the paths written."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    rows = ['figure,frequency_hz,tip_amplitude_m,model_speed_mps,fish_speed_mps,model_sw,fish_sw']
    for name, points in (('9-10', grid), ('11', line)):
        for p in points:
            fish = _optional(p.fish_speed, '.4f')
            fish_sw = _optional(p.swimming_number(p.fish_speed), '.4f')
            rows.append(f'{name},{p.frequency_hz:.2f},{p.tip_amplitude_m:.3f},'
                        f'{p.model_speed:.4f},{fish},{p.swimming_number(p.model_speed):.4f},'
                        f'{fish_sw}')
    paths = [out / 'sweep.csv']
    paths[0].write_text('\n'.join(rows) + '\n')
    for figure, quantity in (('fig9_speed.png', 'speed'), ('fig10_swimming_number.png', 'sw')):
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for amplitude in PAPER_GRID_AMPLITUDES_M:
            points = [p for p in grid if p.tip_amplitude_m == amplitude]
            f = [p.frequency_hz for p in points]
            model = [p.model_speed if quantity == 'speed' else p.swimming_number(p.model_speed)
                     for p in points]
            line_ = ax.plot(f, model, '-', label=f'{amplitude * 100:g} cm model (eq 18)')[0]
            if points[0].fish_speed is not None:
                fish_values = [u if quantity == 'speed' else p.swimming_number(u)
                               for p, u in zip(points, _fish_speeds(points))]
                ax.plot(f, fish_values, '--', color=line_.get_color())
        for frequency, _, speed in PAPER_POINTS:
            if frequency <= 3.0:
                value = speed if quantity == 'speed' else speed / (frequency * 0.53)
                ax.plot(frequency, value, 'k*', markersize=12)
        if grid and grid[0].fish_speed is not None:  # --model-only draws no virtual fish
            ax.plot([], [], 'k--', label='virtual fish (dashed)')
        ax.plot([], [], 'k*', label='paper (stated in text)')
        ax.set(xlabel='tail-beat frequency (Hz)',
               ylabel='steady speed (m/s)' if quantity == 'speed' else 'Sw = U / (f L)',
               title='Speed over the paper grid (Fig 9)' if quantity == 'speed'
               else 'Swimming number (Fig 10)')
        legend_beside(ax)
        fig.tight_layout()
        fig.savefig(out / figure, dpi=110, bbox_inches='tight')
        plt.close(fig)
        paths.append(out / figure)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([p.frequency_hz for p in line], [p.model_speed for p in line], '-',
            label='model (eq 18, ideal servos)')
    if line[0].fish_speed is not None:
        ax.plot([p.frequency_hz for p in line], _fish_speeds(line), 'o--',
                label='virtual fish (servo limits)')
    ax.plot(6.5, 0.54, 'k*', markersize=12, label='paper: 0.54 m/s at 6.5 Hz')
    ax.set(xlabel='tail-beat frequency (Hz)', ylabel='steady speed (m/s)',
           title='5 cm tail-tip amplitude (Fig 11)')
    legend_beside(ax)
    fig.tight_layout()
    fig.savefig(out / 'fig11_speed_5cm.png', dpi=110, bbox_inches='tight')
    plt.close(fig)
    paths.append(out / 'fig11_speed_5cm.png')
    return paths


def _fish_speeds(points: list[SweepPoint]) -> list[float]:
    """Return the points' virtual-fish speeds (m/s); raise ValueError if one has none."""
    speeds = [p.fish_speed for p in points if p.fish_speed is not None]
    if len(speeds) != len(points):
        raise ValueError('a sweep with the virtual fish at some points only: every point needs '
                         'its fish_speed to be plotted')
    return speeds


def _optional(value: float | None, spec: str) -> str:
    return '' if value is None else format(value, spec)


def table(grid: list[SweepPoint], line: list[SweepPoint]) -> str:
    """Return the sweep as a text table, the paper's stated points marked."""
    stated = {(f, a): u for f, a, u in PAPER_POINTS if a is not None}
    lines = [f'{"f Hz":>5} {"amp cm":>6} {"model m/s":>9} {"fish m/s":>8} {"model Sw":>8} '
             f'{"fish Sw":>7}  paper']
    for p in [*grid, *line]:
        paper = stated.get((p.frequency_hz, p.tip_amplitude_m))
        note = '' if paper is None else (
            f'U {paper:.3f} m/s (Sw {paper / (p.frequency_hz * p.body_length):.2f})')
        lines.append(f'{p.frequency_hz:5.1f} {p.tip_amplitude_m * 100:6.1f} '
                     f'{p.model_speed:9.3f} {_optional(p.fish_speed, "8.3f"):>8} '
                     f'{p.swimming_number(p.model_speed):8.3f} '
                     f'{_optional(p.swimming_number(p.fish_speed), "7.3f"):>7}  {note}')
    return '\n'.join(lines)
