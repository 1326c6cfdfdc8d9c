# SPDX-License-Identifier: Apache-2.0
"""
Reproduce the paper's section 5.2 point optimisation in both fit modes, side by side.

``python -m wirefish_analysis.reproduce_paper --out out/paper`` fits the CPG to the wave
c1 = 0.15, c2 = 1, k = 8, omega = 2 pi (alpha = 20, b = 0, default geometry) with the tuner's
PSO twice, from the same seed, swarm and iteration budget:

* literal: the paper's problem (v = 1 Hz, eq 1 from rest, the same clock in eq 23 and the CPG,
  eq 24 over [t_s, t_o] = [20, 25] s; ``wirefish_tuner.wave_loss``);
* phase_free: the tuner's default, a different problem (oscillator 1's phase referenced to the
  wave, v chosen so that the network locks at 1 Hz, one locked period scored).

For each it prints the swing-angle RMSE under both definitions of theta-bar, the loss in several
readings beside the paper's 4.6067, the iteration at which the paper's RMSE is first met, and a
check that integrates eq 1 with RK4 from rest on a real time grid at the fit's own v and scores
it on the same clock as the wave. Then Table 1's own figures under both modes and both signs of
eq 23. Writes fig6a.png, fig6b.png, fig7a.png, fig7bc.png and summary.json. Exit 0 when both
fits meet the paper's RMSE.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import json
from pathlib import Path
import sys
from typing import Any

import numpy as np
from wirefish_common.plotting import legend_beside
from wirefish_common.progress import end_line, Progress
from wirefish_cpg.gait_library import FitMode
from wirefish_cpg.oscillator import CpgParameters, NetworkArrays, simulate
from wirefish_kinematics.body_wave import swing_angles
from wirefish_kinematics.wire_coupling import bend_angles
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.tuning import fit_gait, FitResult
from wirefish_tuner.wave_loss import (desired_swing_angles, literal_waveform_loss,
                                      literal_waveform_swing_rmse_deg, PARAMETER_NAMES,
                                      position_of, swarm_loss, swarm_swing_rmse_deg, ThetaBar,
                                      WaveFitProblem)

PAPER_RMSE_DEG = (1.7165, 1.2817)
PAPER_LOSS = 4.6067  # Fig 6(a), units and window unstated
TABLE1 = CpgParameters()  # Table 1, v = 1 Hz, alpha = 20, b = 0
DEFAULT_ITERATIONS = 300  # the literal problem needs more than 100 (see the README)
# The integration check's RK4 step: the window grid (1/48 s) divided into this many steps.
CHECK_SUBSTEPS = 20


def loss_readings(loss_m_s: float, problem: WaveFitProblem) -> dict[str, float]:
    """
    Return eq 24's value ``loss_m_s`` (m*s over [t_s, t_o]) in the readings tried for 4.6067.

    The paper states neither units nor window nor quadrature: lengths in m, cm or mm, over the
    whole window or per period. (A plain sum of e(t_n) in m over samples every 10 ms or 1 ms
    is the cm*s or mm*s reading: sum = integral / dt.)
    """
    periods = (problem.window_end_s - problem.window_start_s) * problem.wave.frequency_hz
    readings = {}
    for unit, scale in (('m', 1.0), ('cm', 100.0), ('mm', 1000.0)):
        readings[f'{unit}*s over [t_s, t_o]'] = loss_m_s * scale
        readings[f'{unit}*s per period'] = loss_m_s * scale / periods
    return readings


def closest_reading(readings: dict[str, float]) -> tuple[str, float]:
    """Return the reading closest to the paper's 4.6067 (by ratio) and its value."""
    name = min(readings, key=lambda k: abs(np.log(readings[k] / PAPER_LOSS)))
    return name, readings[name]


def integrated_check(params: CpgParameters, problem: WaveFitProblem) -> dict:
    """
    Integrate eq 1 with RK4 from rest at ``params``' own v and score it on eq 23's clock.

    Returns the literal loss (m*s) and RMSE (degrees) over [t_s, t_o] of the integrated outputs
    and the locked frequency measured from them (Hz): upward zero crossings of Theta_1 in the
    window (NaN when there are fewer than two).
    """
    times = problem.window_times()
    spacing = float(times[1] - times[0])
    t, angles, _, _ = simulate(NetworkArrays.from_parameters(params), problem.window_end_s,
                               spacing / CHECK_SUBSTEPS, record_every=CHECK_SUBSTEPS)
    first = int(round(problem.window_start_s / spacing))
    window = angles[first:first + times.size]
    assert np.allclose(t[first:first + times.size], times, atol=1e-9)
    # Upward zero crossings of Theta_1, placed by linear interpolation between samples.
    theta1 = window[:, 0]
    up = np.flatnonzero((theta1[:-1] < 0.0) & (theta1[1:] >= 0.0))
    crossings = times[up] + spacing * theta1[up] / (theta1[up] - theta1[up + 1])
    measured = ((crossings.size - 1) / (crossings[-1] - crossings[0])
                if crossings.size >= 2 else float('nan'))
    return {'v_hz': params.frequency_hz, 'step_s': spacing / CHECK_SUBSTEPS,
            'loss': float(literal_waveform_loss(window[None], problem)[0]),
            'rmse_theta_deg': literal_waveform_swing_rmse_deg(window[None], problem)[0].tolist(),
            'measured_frequency_hz': float(measured)}


def mode_summary(mode: str, fit: FitResult, problem: WaveFitProblem) -> dict:
    """Return the printed figures of one fit mode."""
    history = fit.pso.position_history
    rmse_history = swarm_swing_rmse_deg(history, problem, mode)
    at_paper = np.flatnonzero(np.all(rmse_history <= PAPER_RMSE_DEG, axis=1))
    best = fit.pso.best_position[None]
    readings = loss_readings(fit.loss if mode == FitMode.LITERAL
                             else fit.loss * problem.wave.frequency_hz
                             * (problem.window_end_s - problem.window_start_s), problem)
    return {
        'mode': mode, 'iterations': fit.iterations, 'wall_s': fit.elapsed_s,
        'loss': fit.loss,
        'loss_unit': 'm*s over [t_s, t_o]' if mode == FitMode.LITERAL else 'm*s per period',
        'loss_readings': readings,
        'rmse_theta_deg': {d: swarm_swing_rmse_deg(best, problem, mode, d)[0].tolist()
                           for d in ThetaBar},
        'iteration_at_paper_rmse': int(at_paper[0]) if at_paper.size else None,
        'params': dict(zip(PARAMETER_NAMES, fit.pso.best_position.tolist())),
        'frequency_hz': fit.params.frequency_hz,
        'integrated_check': integrated_check(fit.params, problem),
    }


def table1_summary(problem: WaveFitProblem) -> dict:
    """Return Table 1's loss and RMSE (both theta-bar) under both modes and both signs."""
    table1 = position_of(TABLE1)[None]
    out = {}
    for sign, reverse in (('tailward (-omega t)', False), ('headward (+omega t, as printed)',
                                                           True)):
        p = replace(problem, reverse_wave=reverse)
        out[sign] = {mode: {'loss': float(swarm_loss(table1, p, mode)[0]),
                            'rmse_theta_deg': {d: swarm_swing_rmse_deg(table1, p, mode, d)[0]
                                               .tolist() for d in ThetaBar}}
                     for mode in FitMode}
    return out


def run(out_dir: Path, seed: int = 0,
        options: PsoOptions = PsoOptions(max_iterations=DEFAULT_ITERATIONS),
        progress: Progress | None = None) -> dict:
    """
    Fit the section 5.2 case in both modes, write the figures into ``out_dir``.

    ``progress`` (``len(FitMode) * (max_iterations + 1)`` steps) is told after every PSO
    iteration of each fit.
    """
    problem = WaveFitProblem()
    fits: dict[str, FitResult] = {}
    for index, mode in enumerate(FitMode):
        first = index * (options.max_iterations + 1)

        def step(iteration: int, loss: float, _best, first: int = first,
                 mode: FitMode = mode):
            if progress is not None:
                progress.step(first + iteration + 1, f'{mode} fit: loss {loss:.4g}')

        fits[mode] = fit_gait(problem, np.random.default_rng(seed), options, mode=mode,
                              callback=step)
    summary: dict[str, Any] = {
        'wave': {'c1': 0.15, 'c2': 1.0, 'k': 8.0, 'frequency_hz': 1.0},
        'window_s': [problem.window_start_s, problem.window_end_s],
        'seed': seed, 'swarm_size': options.swarm_size,
        'max_iterations': options.max_iterations,
        'paper_rmse_theta_deg': list(PAPER_RMSE_DEG), 'paper_loss': PAPER_LOSS,
        'modes': {mode: mode_summary(mode, fit, problem) for mode, fit in fits.items()},
        'table1': table1_summary(problem),
    }
    table1_literal = summary['table1']['tailward (-omega t)'][FitMode.LITERAL]['loss']
    summary['table1_literal_loss_readings'] = loss_readings(table1_literal, problem)
    out_dir.mkdir(parents=True, exist_ok=True)
    _plot(out_dir, fits, problem, summary)
    (out_dir / 'summary.json').write_text(json.dumps(summary, indent=2) + '\n')
    return summary


def _plot(out_dir: Path, fits: dict[str, FitResult], problem: WaveFitProblem,
          summary: dict) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for mode, fit in fits.items():
        unit = summary['modes'][mode]['loss_unit']
        ax.semilogy(fit.pso.loss_history, 'o-', ms=2, label=f'{mode} ({unit})')
    ax.set(xlabel='iteration', ylabel='best loss, eq 24 (m s)',
           title='Fig 6(a): convergence of the loss')
    legend_beside(ax)
    fig.tight_layout()
    fig.savefig(out_dir / 'fig6a.png', dpi=110, bbox_inches='tight')
    plt.close(fig)

    literal = fits[FitMode.LITERAL]
    labels = ['$\\omega_{12}$', '$\\omega_{21}$', '$\\varphi_{12}$ (rad)',
              '$\\varphi_{21}$ (rad)', '$R_1$ (rad)', '$R_2$ (rad)']
    converged = int(np.argmax(literal.pso.loss_history <= literal.loss))
    fig, axes = plt.subplots(3, 2, figsize=(8, 7), sharex=True)
    for k, ax in enumerate(axes.flat):
        ax.plot(literal.pso.position_history[:, k], '-', lw=1.2)
        ax.axvline(converged, color='red', ls=':', label='last improvement')
        ax.set_ylabel(labels[k])
    for ax in axes[-1]:
        ax.set_xlabel('iteration')
    legend_beside(axes[0, 1])
    fig.suptitle('Fig 6(b): the six CPG parameters of the best particle (literal mode)')
    fig.tight_layout()
    fig.savefig(out_dir / 'fig6b.png', dpi=110, bbox_inches='tight')
    plt.close(fig)

    t, angles, _, _ = simulate(NetworkArrays.from_parameters(literal.params),
                               problem.window_end_s, 1e-3, record_every=5)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(t, angles[:, 0], lw=0.8, label='$\\Theta_1$')
    ax.plot(t, angles[:, 1], lw=0.8, label='$\\Theta_2$')
    ax.axvspan(problem.window_start_s, problem.window_end_s, color='gray', alpha=0.2,
               label='[$t_s$, $t_o$]')
    ax.set(xlabel='t (s)', ylabel='CPG output (rad)',
           title='Fig 7(a): CPG outputs from rest (eq 1, literal fit, v = 1 Hz)')
    legend_beside(ax)
    fig.tight_layout()
    fig.savefig(out_dir / 'fig7a.png', dpi=110, bbox_inches='tight')
    plt.close(fig)

    times = problem.window_times()
    servo = angles[np.searchsorted(t, times - 1e-9)]
    beta1, beta2 = bend_angles(servo[:, 0], servo[:, 1], problem.geometry)
    theta = np.degrees(np.stack(swing_angles(beta1, beta2, problem.geometry), axis=-1))
    expected = np.degrees(desired_swing_angles(problem, ThetaBar.AXIAL, times))
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for i, color in enumerate(('C0', 'C1')):
        ax.plot(times, expected[:, i], '--', color=color,
                label=f'expected $\\bar\\theta_{i + 1}$')
        ax.plot(times, theta[:, i], '-', color=color, label=f'predicted $\\theta_{i + 1}$')
    ax.set(xlabel='t (s), the window [$t_s$, $t_o$]', ylabel='swing angle (deg)',
           title='Fig 7(b, c): expected and predicted swing angles (literal fit)')
    legend_beside(ax)
    fig.tight_layout()
    fig.savefig(out_dir / 'fig7bc.png', dpi=110, bbox_inches='tight')
    plt.close(fig)


def _rmse(pair: list[float]) -> str:
    return f'{pair[0]:.4f} / {pair[1]:.4f}'


def report(s: dict) -> str:
    """Return the printed side-by-side report of ``run``'s summary."""
    modes = s['modes']
    lines = [f'section 5.2 fit, both modes: seed {s["seed"]}, {s["swarm_size"]} particles, '
             f'at most {s["max_iterations"]} iterations; window [t_s, t_o] = '
             f'{s["window_s"][0]:g}-{s["window_s"][1]:g} s; paper RMSE '
             f'{_rmse(list(PAPER_RMSE_DEG))} deg, loss {PAPER_LOSS}',
             f'{"":44s}{"literal (the paper)":>24s}{"phase_free (other problem)":>28s}']

    def row(label: str, key) -> None:
        lines.append(f'{label:44s}{key(modes[FitMode.LITERAL]):>24s}'
                     f'{key(modes[FitMode.PHASE_FREE]):>28s}')

    row('iterations (wall s)', lambda m: f'{m["iterations"]} ({m["wall_s"]:.2f})')
    row('RMSE th1/th2 deg, theta-bar axial',
        lambda m: _rmse(m['rmse_theta_deg'][ThetaBar.AXIAL]))
    row('RMSE th1/th2 deg, theta-bar chord',
        lambda m: _rmse(m['rmse_theta_deg'][ThetaBar.CHORD]))
    row('paper RMSE first met at iteration',
        lambda m: str(m['iteration_at_paper_rmse']))
    row('loss (m*s), own definition', lambda m: f'{m["loss"]:.5g}')
    row('v (Hz)', lambda m: f'{m["frequency_hz"]:.4f}')
    row('check: RK4 from rest at own v: loss m*s',
        lambda m: f'{m["integrated_check"]["loss"]:.5g}')
    row('  same clock as eq 23: RMSE th1/th2 deg',
        lambda m: _rmse(m['integrated_check']['rmse_theta_deg']))
    row('  locked frequency measured (Hz)',
        lambda m: f'{m["integrated_check"]["measured_frequency_hz"]:.4f}')
    lines.append('  params literal:    ' + ', '.join(
        f'{k} {v:+.3f}' for k, v in modes[FitMode.LITERAL]['params'].items()))
    lines.append('  params phase_free: ' + ', '.join(
        f'{k} {v:+.3f}' for k, v in modes[FitMode.PHASE_FREE]['params'].items()))
    lines.append('')
    lines.append("Table 1 (the paper's parameters)            loss (m*s)   RMSE axial     "
                 'RMSE chord   (loss: literal over [t_s, t_o], phase_free per period)')
    for sign, by_mode in s['table1'].items():
        for mode, f in by_mode.items():
            lines.append(f'  {sign:32s} {mode:10s} {f["loss"]:9.5f}  '
                         f'{_rmse(f["rmse_theta_deg"]["axial"]):>14s} '
                         f'{_rmse(f["rmse_theta_deg"]["chord"]):>14s}')
    lines.append('')
    lines.append(f"the loss in the readings tried for the paper's {PAPER_LOSS} "
                 '(Table 1 literal | literal fit):')
    table1_readings = s['table1_literal_loss_readings']
    fit_readings = modes[FitMode.LITERAL]['loss_readings']
    for name, value in table1_readings.items():
        lines.append(f'  {name:46s} {value:12.5g} ({value / PAPER_LOSS:7.3f} x) | '
                     f'{fit_readings[name]:10.5g}')
    name, value = closest_reading(table1_readings)
    per_period_cm = table1_readings['cm*s per period']
    lines.append(f'  closest for Table 1: {name} = {value:.4g} ({value / PAPER_LOSS:.3f} x); '
                 f'cm*s would equal {PAPER_LOSS} over {PAPER_LOSS / per_period_cm:.2f} periods '
                 '(window and units unstated: not pinned)')
    lines.append('  (a plain sum of e(t_n) in m every 10 ms / 1 ms is the cm*s / mm*s reading)')
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run the reproduction and print its figures; return 0 when both fits meet the paper."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=Path('out/paper'), help='output dir')
    parser.add_argument('--seed', type=int, default=0, help='PSO seed')
    parser.add_argument('--swarm', type=int, default=PsoOptions.swarm_size,
                        help='PSO particles of each fit')
    parser.add_argument('--iterations', type=int, default=DEFAULT_ITERATIONS,
                        help='PSO iterations of each fit (at most)')
    args = parser.parse_args(argv)
    options = PsoOptions(swarm_size=args.swarm, max_iterations=args.iterations)
    progress = Progress('reproduce_paper', len(FitMode) * (options.max_iterations + 1))
    try:
        s = run(args.out, args.seed, options, progress)
    except KeyboardInterrupt:
        end_line()
        print('reproduce_paper: interrupted (Ctrl-C)', file=sys.stderr)
        return 130
    print(report(s))
    print(f'figures: {args.out}/fig6a.png fig6b.png fig7a.png fig7bc.png summary.json')
    met = all(all(a <= b for a, b in zip(m['rmse_theta_deg'][ThetaBar.AXIAL], PAPER_RMSE_DEG))
              for m in s['modes'].values())
    return 0 if met else 1


if __name__ == '__main__':
    sys.exit(main())
