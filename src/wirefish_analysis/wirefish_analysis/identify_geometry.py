# SPDX-License-Identifier: Apache-2.0
"""
Recover the fish's unpublished geometry from the paper's indirect evidence.

``python -m wirefish_analysis.identify_geometry --out config.yaml`` fits l1, l2, l3, r1, r2,
R_D (= R_D1 = R_D2) and C_D, within physical bounds, to what the paper does state:

=====================  ==============================================  ==================
evidence               model quantity                                  tolerance (weight)
=====================  ==============================================  ==================
RMSE of section 5.2    Table 1's theta_1, theta_2 RMSE, literal mode   0.1 deg each
Table 1 is the optimum gain of the literal loss within Table 1's       1 % of the loss
                       printed precision (+-0.005 on each value)
Figs 9-10 amplitudes   Table 1's tail-tip half amplitude at 1 Hz       inside 4-9 cm, else
                                                                       0.5 cm
0.39 m/s at 3 Hz       eq 18 with Table 1 locked at 3 Hz               0.045 m/s
530 mm body            l1 + l2 + l3 <= 0.53 m                          1 cm beyond
=====================  ==============================================  ==================

The objective is the sum of squared (miss / tolerance): one unit is one tolerance on one piece
of evidence. The literal mode is the paper's problem (``wirefish_tuner.wave_loss``: v = 1 Hz,
eq 1 from rest, window 20-25 s, theta-bar 'axial', the tail-ward wave). The tolerances: the
paper prints its RMSE to 4 decimals but not its theta-bar or window (the two theta-bar readings
differ by ~0.1 deg for Table 1); Table 1 is printed to 2 decimals; 0.045 m/s is the paper's
own simulation-vs-experiment speed RMSE.

C_D is profiled out during the search (eq 18 solved for the 3 Hz speed, exact) and scanned
like the others afterwards. The search is the project's PSO (eqs 26-27) over the six lengths,
polished by Nelder-Mead, from several independent starts. Uncertainty: for each parameter, the
range over which the objective stays within 1 of its minimum with the others held (how flat it
is along that direction), joined with the values of the starts that end within 1 of the best
(equally good minima elsewhere); "pinned" when that is within +-10 %. Two directions are flat
by construction and said so: the kinematics see R_D only through R_D / r1 and R_D / r2
(eqs 3-4), and eq 18 sees C_D only as C_D S_c.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from pathlib import Path
import re
import sys

import numpy as np
from scipy.optimize import brentq, minimize
from wirefish_analysis.calibrate_drag import (calibrated_drag_coefficient, CALIBRATION_HZ,
                                              CALIBRATION_SPEED, least_squares_drag)
from wirefish_common.progress import Progress
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.table1_gait import locked_speed_estimate, table1_locked_at, tip_half_amplitude
from wirefish_kinematics.geometry import FishGeometry
from wirefish_tuner.pso import minimise, PsoOptions
from wirefish_tuner.wave_loss import (literal_body_wave_loss, literal_swing_rmse_deg,
                                      position_of, WaveFitProblem)

PARAMETERS = ('l1', 'l2', 'l3', 'r1', 'r2', 'rd', 'drag_coefficient')
LENGTHS = PARAMETERS[:6]
# Physical bounds (m; C_D dimensionless): links and fin of a 530 mm fish whose head holds the
# drive cabin; wire offsets within the 106 mm body's half width; reels inside the head.
LOWER = np.array([0.02, 0.02, 0.02, 0.005, 0.005, 0.005, 1e-3])
UPPER = np.array([0.30, 0.30, 0.20, 0.053, 0.053, 0.040, 10.0])
PAPER_RMSE_DEG = (1.7165, 1.2817)
RMSE_TOLERANCE_DEG = 0.1
GAIN_TOLERANCE = 0.01
PRINTED_PRECISION = 0.005  # Table 1 is printed to 2 decimals
AMPLITUDE_RANGE_M = (0.04, 0.09)
AMPLITUDE_TOLERANCE_M = 0.005
SPEED_TOLERANCE = 0.045  # m/s
BODY_LENGTH_M = 0.53
LENGTH_TOLERANCE_M = 0.01
TABLE1 = position_of(CpgParameters())
# A value counts as pinned when its uncertainty (see ``report``) is within +-10 % of it.
PINNED_HALF_WIDTH = 0.10


def geometry_of(x: np.ndarray, base: FishGeometry = FishGeometry()) -> FishGeometry:
    """Return ``base`` with l1, l2, l3, r1, r2, R_D1 = R_D2 = rd (and C_D, if given) of x."""
    values = dict(zip(PARAMETERS, (float(v) for v in x)))
    rd = values.pop('rd')
    return replace(base, rd1=rd, rd2=rd, **values)


@dataclass(frozen=True)
class Evidence:
    """The model's side of each piece of evidence for one geometry."""

    rmse_deg: tuple[float, float]  # Table 1, literal mode, theta-bar axial
    optimality_gain: float  # relative loss gain within Table 1's printed precision
    tip_amplitude_m: float  # Table 1 at 1 Hz
    speed_3hz: float  # eq 18, Table 1 locked at 3 Hz (m/s)
    total_length_m: float  # l1 + l2 + l3


def optimality_gain(problem: WaveFitProblem) -> float:
    """
    Return sum_k |dL/dlambda_k| h / L at Table 1: the literal loss's first-order gain in h.

    Central differences with h = ``PRINTED_PRECISION`` on each of the six values (one swarm
    of 13 evaluations).
    """
    steps = PRINTED_PRECISION * np.eye(6)
    swarm = np.vstack([TABLE1, TABLE1 + steps, TABLE1 - steps])
    loss = literal_body_wave_loss(swarm, problem)
    return float(np.sum(np.abs(loss[1:7] - loss[7:]) / 2.0) / loss[0])


def evidence(geometry: FishGeometry) -> Evidence:
    """Return the model's figures for ``geometry`` (see the module docstring)."""
    problem = WaveFitProblem(geometry=geometry)
    rmse = literal_swing_rmse_deg(TABLE1[None], problem)[0]
    return Evidence(rmse_deg=(float(rmse[0]), float(rmse[1])),
                    optimality_gain=optimality_gain(problem),
                    tip_amplitude_m=tip_half_amplitude(table1_locked_at(1.0), geometry),
                    speed_3hz=locked_speed_estimate(table1_locked_at(CALIBRATION_HZ),
                                                    geometry).speed,
                    total_length_m=geometry.tail_length)


def residuals(e: Evidence) -> dict[str, float]:
    """Return each piece of evidence's miss divided by its tolerance."""
    low, high = AMPLITUDE_RANGE_M
    outside = max(low - e.tip_amplitude_m, e.tip_amplitude_m - high, 0.0)
    return {'rmse theta1': (e.rmse_deg[0] - PAPER_RMSE_DEG[0]) / RMSE_TOLERANCE_DEG,
            'rmse theta2': (e.rmse_deg[1] - PAPER_RMSE_DEG[1]) / RMSE_TOLERANCE_DEG,
            'Table 1 optimal': e.optimality_gain / GAIN_TOLERANCE,
            'tip amplitude': outside / AMPLITUDE_TOLERANCE_M,
            'speed 3 Hz': (e.speed_3hz - CALIBRATION_SPEED) / SPEED_TOLERANCE,
            'length': max(e.total_length_m - BODY_LENGTH_M, 0.0) / LENGTH_TOLERANCE_M}


def objective(x: np.ndarray, base: FishGeometry = FishGeometry()) -> float:
    """Return the sum of squared residuals of the seven parameters x; inf outside the box."""
    x = np.asarray(x, dtype=float)
    if np.any(x < LOWER) or np.any(x > UPPER):
        return math.inf
    return float(sum(r * r for r in residuals(evidence(geometry_of(x, base))).values()))


def with_profiled_drag(lengths: np.ndarray, base: FishGeometry = FishGeometry()) -> np.ndarray:
    """Return the seven parameters: the six lengths and the C_D that meets 0.39 m/s at 3 Hz."""
    c_d = calibrated_drag_coefficient(geometry_of(np.append(lengths, 1.0), base))
    return np.append(lengths, c_d)


def profiled_objective(lengths: np.ndarray, base: FishGeometry = FishGeometry()) -> float:
    """Return the objective of six lengths with C_D profiled out (inf outside the bounds)."""
    lengths = np.asarray(lengths, dtype=float)
    if np.any(lengths < LOWER[:6]) or np.any(lengths > UPPER[:6]):
        return math.inf
    return objective(with_profiled_drag(lengths, base), base)


@dataclass(frozen=True)
class Identification:
    """
    The identified parameters (7,), their objective, the flat range of each, every start.

    ``starts`` holds (parameters (7,), objective) of each independent search, best first: how
    far apart equally good minima lie is the other half of the uncertainty.
    """

    x: np.ndarray
    objective: float
    ranges: tuple[tuple[float, float, bool, bool], ...]  # low, high, low at bound, high at bound
    starts: tuple[tuple[np.ndarray, float], ...]


def flat_range(x: np.ndarray, k: int, rise: float = 1.0) -> tuple[float, float, bool, bool]:
    """
    Return the interval of parameter k where the objective is within ``rise`` of x's.

    NaN ends when the objective at x is not finite (no search found an admissible point).
    """
    floor = objective(x)
    if not math.isfinite(floor):
        return math.nan, math.nan, False, False

    def excess(value: float) -> float:
        moved = x.copy()
        moved[k] = value
        found = objective(moved)
        return (found if math.isfinite(found) else 1e300) - floor - rise

    ends = []
    for bound in (LOWER[k], UPPER[k]):
        if excess(bound) <= 0.0:
            ends.append((float(bound), True))
        else:
            ends.append((float(brentq(excess, x[k], bound, xtol=1e-6 * abs(bound))), False))
    return ends[0][0], ends[1][0], ends[0][1], ends[1][1]


def steps_of_a_start(options: PsoOptions, polish_iterations: int) -> int:
    """Return a start's progress steps: its swarm's evaluations, at most one per polish step."""
    return options.swarm_size * (options.max_iterations + 1) + polish_iterations


def identify(rng: np.random.Generator, options: PsoOptions = PsoOptions(max_iterations=60),
             polish_iterations: int = 2000, starts: int = 1,
             progress: Progress | None = None) -> Identification:
    """
    Search the six lengths ``starts`` times (PSO, then Nelder-Mead), then C_D; keep the best.

    Each start draws from its own child of ``rng`` (``Generator.spawn``), so a run is
    reproducible from one seed. ``progress`` (``starts * steps_of_a_start`` steps) is told
    after every swarm iteration and polish step; a start that stops early skips its rest.
    """
    def swarm_objective(positions: np.ndarray) -> np.ndarray:
        return np.array([profiled_objective(p) for p in positions])

    per_start = steps_of_a_start(options, polish_iterations)
    found = []
    for index, child in enumerate(rng.spawn(starts)):
        first = index * per_start

        def swarm_step(iteration: int, loss: float, _best: np.ndarray) -> None:
            if progress is not None:
                progress.step(first + options.swarm_size * (iteration + 1),
                              f'search {index + 1}/{starts}, swarm: best {loss:.4g}')

        polish_steps = 0

        def polish_step(_x: np.ndarray) -> None:
            nonlocal polish_steps
            polish_steps += 1
            if progress is not None:
                progress.step(first + options.swarm_size * (options.max_iterations + 1)
                              + polish_steps, f'search {index + 1}/{starts}, polish')

        swarm = minimise(swarm_objective, LOWER[:6], UPPER[:6], child, options,
                         callback=swarm_step)
        polished = minimize(profiled_objective, swarm.best_position, method='Nelder-Mead',
                            bounds=list(zip(LOWER[:6], UPPER[:6])), callback=polish_step,
                            options={'xatol': 1e-6, 'fatol': 1e-6,
                                     'maxiter': polish_iterations})
        if progress is not None:
            progress.step(first + per_start, f'search {index + 1}/{starts} done')
        best = polished.x if polished.fun < swarm.best_loss else swarm.best_position
        x = with_profiled_drag(best)
        found.append((x, objective(x)))
    found.sort(key=lambda item: item[1])
    x, value = found[0]
    return Identification(x=x, objective=value,
                          ranges=tuple(flat_range(x, k) for k in range(len(PARAMETERS))),
                          starts=tuple(found))


def scaling_flatness(x: np.ndarray, factor: float = 0.8) -> tuple[float, float]:
    """Return the objective's change when (r1, r2, R_D) and when C_D S_c are scaled together."""
    scaled = x.copy()
    scaled[3:6] *= factor  # down: the lower bounds are far below any fitted value
    base = geometry_of(x)
    drag_area = replace(base, drag_coefficient=base.drag_coefficient / factor,
                        wetted_area=base.wetted_area * factor)
    e = residuals(evidence(drag_area))
    return (objective(scaled) - objective(x),
            float(sum(r * r for r in e.values())) - objective(x))


GEOMETRY_KEYS = ('l1', 'l2', 'l3', 'r1', 'r2', 'rd1', 'rd2', 'drag_coefficient')


def parameter_file_text(template: str, geometry: FishGeometry, header: str) -> str:
    """
    Return ``template`` (the text of config/wirefish.yaml) with the geometry keys replaced.

    Every ``key: value`` line of ``GEOMETRY_KEYS`` in any node's block takes the geometry's
    value (comments after the value are replaced by 'identified'); all else is kept.
    """
    def substitute(match: re.Match) -> str:
        key = match.group(2)
        return f'{match.group(1)}{key}: {getattr(geometry, key):.6g}  # identified'

    pattern = re.compile(r'^(\s+)(' + '|'.join(GEOMETRY_KEYS) + r'):\s*[^\n]*$', re.MULTILINE)
    return header + pattern.sub(substitute, template)


def default_template() -> Path:
    """Return the installed config/wirefish.yaml of wirefish_bringup."""
    from ament_index_python.packages import get_package_share_directory
    return Path(get_package_share_directory('wirefish_bringup'), 'config', 'wirefish.yaml')


def report(result: Identification) -> str:
    """Return the printed table: parameters, ranges, evidence before and after."""
    today = FishGeometry()
    current = np.array([today.l1, today.l2, today.l3, today.r1, today.r2, today.rd1,
                        today.drag_coefficient])
    lines = [f'objective (sum of squared misses / tolerance): identified {result.objective:.4g}, '
             f"today's estimates {objective(current):.4g}",
             f'{"parameter":18s} {"today":>9s} {"identified":>11s}   {"+1, others held":>18s}'
             f'   {"starts within +1":>16s}  verdict']
    near = np.array([x for x, value in result.starts if value <= result.objective + 1.0])
    for k, name in enumerate(PARAMETERS):
        low, high, low_bound, high_bound = result.ranges[k]
        spread = (float(near[:, k].min()), float(near[:, k].max()))
        # Uncertainty: the +1 range along the parameter joined with the equally good minima.
        half = 0.5 * (max(high, spread[1]) - min(low, spread[0])) / result.x[k]
        if name in ('r1', 'r2', 'rd'):
            verdict = 'only R_D / r_i is identified (below)'
        elif min(result.x[k] - LOWER[k], UPPER[k] - result.x[k]) <= 1e-6 * UPPER[k]:
            verdict = 'at the physical bound: the evidence pushes beyond it'
        elif half <= PINNED_HALF_WIDTH:
            verdict = f'pinned (+-{100 * half:.0f} %)'
        else:
            verdict = f'NOT pinned (+-{100 * half:.0f} %)'
        lines.append(f'{name:18s} {current[k]:9.4f} {result.x[k]:11.4f}   '
                     f'[{low:.4f}{"*" if low_bound else ""}, '
                     f'{high:.4f}{"*" if high_bound else ""}]   '
                     f'[{spread[0]:.4f}, {spread[1]:.4f}]  {verdict}')
    lines.append(f'{len(result.starts)} independent starts (objective, then the parameters '
                 'above):')
    for x, value in result.starts:
        lines.append(f'  {value:9.4g}  ' + ' '.join(f'{v:.4f}' for v in x))
    ratios, drag_area = scaling_flatness(result.x)
    lines += [f'R_D / r1 = {result.x[5] / result.x[3]:.4f}, R_D / r2 = '
              f'{result.x[5] / result.x[4]:.4f}: scaling r1, r2, R_D together by 0.8 changes '
              f'the objective by {ratios:.2g} -- R_D is not pinned, only these ratios are',
              f'C_D S_c = {result.x[6] * today.wetted_area:.4f} m^2 (S_c = {today.wetted_area} '
              f'm^2 estimated): scaling C_D up and S_c down by 1.25 changes the objective by '
              f'{drag_area:.2g} -- C_D is pinned only given S_c',
              '(* = the range reaches the physical bound)', '',
              f'{"evidence":18s} {"paper":>12s} {"today":>14s} {"identified":>14s}']
    before, after = evidence(geometry_of(current)), evidence(geometry_of(result.x))
    rows = (('RMSE theta1 deg', f'{PAPER_RMSE_DEG[0]}', lambda e: f'{e.rmse_deg[0]:.4f}'),
            ('RMSE theta2 deg', f'{PAPER_RMSE_DEG[1]}', lambda e: f'{e.rmse_deg[1]:.4f}'),
            ('Table 1 gain', 'optimal', lambda e: f'{100 * e.optimality_gain:.2f} %'),
            ('tip amp 1 Hz cm', '4-9', lambda e: f'{100 * e.tip_amplitude_m:.2f}'),
            ('U at 3 Hz m/s', f'{CALIBRATION_SPEED}', lambda e: f'{e.speed_3hz:.4f}'),
            ('l1+l2+l3 m', f'<= {BODY_LENGTH_M}', lambda e: f'{e.total_length_m:.4f}'))
    for label, paper, shown in rows:
        lines.append(f'{label:18s} {paper:>12s} {shown(before):>14s} {shown(after):>14s}')
    try:
        fit = least_squares_drag(geometry_of(result.x))
        lines.append(f'least-squares C_D over the 3 speed points with the identified geometry: '
                     f'{fit.drag_coefficient:.4f}, speed RMSE {fit.rmse:.4f} m/s (paper 0.045)')
    except ValueError as error:
        lines.append(f'least-squares C_D over the 3 speed points: not possible ({error})')
    return '\n'.join(lines)


if __name__ == '__main__':
    from wirefish_analysis.verb.identify_geometry import main
    sys.exit(main())
