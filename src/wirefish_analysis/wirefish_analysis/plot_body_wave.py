# SPDX-License-Identifier: Apache-2.0
"""
Plot the paper's Fig 7(b-d) for a locked pair of servo sinusoids.

``ros2 run wirefish_kinematics plot_body_wave --out DIR`` (or ``python -m
wirefish_analysis.plot_body_wave``) writes

* ``fig7bc_swing_angles.png``: expected swing angles theta-bar_i (eq 23) and the predicted
  theta_i (eqs 2-15) over one period, with their RMSE (paper: 1.7165 deg, 1.2817 deg);
* ``fig7d_tail_period.png``: the tail (solid) at ``--snapshots`` instants of one period, the
  desired wave dotted, the ends of L1 (circles) and L2 (squares).

The servo angles are the CPG's steady state Theta_1 = R1 cos(wt), Theta_2 = R2 cos(wt + Delta).
The defaults are Table 1 (R1 = 0.38, R2 = 0.47 rad) with its locked phase difference
Delta* = -1.2020 rad (eq 1, wirefish_cpg.steady_state; this package does not import the CPG),
at the wave's frequency, against the section 5.2 wave (c1 = 0.15, c2 = 1, k = 8, 1 Hz). The
desired wave is shown at the tail's phase: its fundamental at q1 peaks with Theta_1.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
import sys

import numpy as np

from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.desired_wave import (desired_lateral_position, desired_swing_angles,
                                              wave_time_at_phase)
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import bend_angles

TABLE1_AMPLITUDES = (0.38, 0.47)
TABLE1_PHASE_DIFFERENCE = -1.2020076916841376  # Delta* of Table 1 (wirefish_cpg)


def one_period(amplitudes: tuple[float, float], phase_difference: float, frequency_hz: float,
               samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return (t (N,) s, oscillator-1 phase (N,) rad, servo angles (N, 2) rad) of one period."""
    t = np.arange(samples) / (samples * frequency_hz)
    phase = 2.0 * math.pi * frequency_hz * t
    angles = np.stack([amplitudes[0] * np.cos(phase),
                       amplitudes[1] * np.cos(phase + phase_difference)], axis=-1)
    return t, phase, angles


def write_figures(out_dir: Path, geometry: FishGeometry, amplitudes: tuple[float, float],
                  phase_difference: float, wave: tuple[float, float, float, float],
                  snapshots: int = 8) -> tuple[float, float]:
    """Write both PNGs into ``out_dir``; return the swing-angle RMSEs (deg)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    c1, c2, k, frequency = wave
    out_dir.mkdir(parents=True, exist_ok=True)
    t, phase, angles = one_period(amplitudes, phase_difference, frequency, 400)
    beta1, beta2 = bend_angles(angles[:, 0], angles[:, 1], geometry)
    theta = np.degrees(np.stack(swing_angles(beta1, beta2, geometry), axis=-1))
    # y(q1) is odd and increasing in Theta_1, so its phase is oscillator 1's (R1 > 0).
    sign_phase = phase + (0.0 if amplitudes[0] >= 0.0 else math.pi)
    tau = wave_time_at_phase(sign_phase, geometry.l1, k, frequency)
    expected = np.degrees(np.stack(desired_swing_angles(tau, c1, c2, k, frequency, geometry),
                                   axis=-1))
    rmse = np.sqrt(np.mean((theta - expected) ** 2, axis=0))

    fig, ax = plt.subplots(figsize=(7, 4))
    for i, color in enumerate(('tab:blue', 'tab:red')):
        ax.plot(t, expected[:, i], ':', color=color, label=f'expected theta-bar{i + 1}')
        ax.plot(t, theta[:, i], '-', color=color,
                label=f'predicted theta{i + 1} (RMSE {rmse[i]:.2f} deg)')
    ax.set(xlabel='t (s), one period', ylabel='swing angle (deg)',
           title='Fig 7(b, c): expected vs predicted swing angles')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_dir / 'fig7bc_swing_angles.png', dpi=110)
    plt.close(fig)

    stations = np.linspace(0.0, geometry.tail_length, 100)
    fig, ax = plt.subplots(figsize=(7, 4))
    colors = plt.cm.viridis(np.linspace(0.0, 1.0, snapshots))
    for n, color in zip(np.linspace(0, t.size, snapshots, endpoint=False).astype(int), colors):
        x, y = body_positions(stations, beta1[n], beta2[n], geometry)
        ax.plot(x, y, '-', color=color, label=f't = {t[n]:.3f} s')
        ax.plot(stations, desired_lateral_position(stations, tau[n], c1, c2, k, frequency),
                ':', color=color)
        ends_x, ends_y = body_positions(np.array(geometry.link_end_stations), beta1[n],
                                        beta2[n], geometry)
        ax.plot(ends_x[0], ends_y[0], 'o', color=color, mfc='none')
        ax.plot(ends_x[1], ends_y[1], 's', color=color, mfc='none')
    ax.set(xlabel='x in tail_base (m)', ylabel='y in tail_base (m, to the right)',
           title='Fig 7(d): tail over one period (dotted: desired wave; o: O1, s: O2)')
    ax.set_aspect('equal')
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out_dir / 'fig7d_tail_period.png', dpi=110)
    plt.close(fig)
    return float(rmse[0]), float(rmse[1])


def main(argv: list[str] | None = None) -> int:
    """Parse the options, write the figures and print the RMSEs."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=Path('out/kinematics'),
                        help='output directory')
    parser.add_argument('--amplitudes', type=float, nargs=2, default=TABLE1_AMPLITUDES,
                        metavar=('R1', 'R2'), help='servo amplitudes (rad)')
    parser.add_argument('--phase-difference', type=float, default=TABLE1_PHASE_DIFFERENCE,
                        help='Delta = xi2 - xi1 of the locked CPG (rad)')
    parser.add_argument('--wave', type=float, nargs=4, default=(0.15, 1.0, 8.0, 1.0),
                        metavar=('C1', 'C2', 'K', 'HZ'), help='desired wave of eq 23')
    parser.add_argument('--snapshots', type=int, default=8, help='tails drawn in Fig 7(d)')
    args = parser.parse_args(argv)
    try:
        rmse = write_figures(args.out, FishGeometry(), tuple(args.amplitudes),
                             args.phase_difference, tuple(args.wave), args.snapshots)
    except ValueError as error:
        print(f'plot_body_wave: {error}', file=sys.stderr)
        return 2
    print(f'swing-angle RMSE theta1 {rmse[0]:.4f} deg, theta2 {rmse[1]:.4f} deg '
          '(paper: 1.7165, 1.2817)')
    print(f'wrote {args.out}/fig7bc_swing_angles.png and {args.out}/fig7d_tail_period.png')
    return 0


if __name__ == '__main__':
    sys.exit(main())
