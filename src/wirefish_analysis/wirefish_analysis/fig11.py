# SPDX-License-Identifier: Apache-2.0
"""
Speed of the virtual fish against tail-beat frequency at 5 cm tail-tip amplitude (paper Fig 11).

``python -m wirefish_analysis.fig11 --out out/fig11.png`` runs the sweep (faster than real time,
no ROS) and writes the PNG and the numbers. The gait is Table 1's CPG with both amplitudes
scaled so that the kinematic tail-tip half amplitude with ideal servos is 5 cm; at each
frequency the virtual fish is driven with the CPG's locked output (sampled at 200 Hz, as
cpg_node publishes it) and its mean surge speed is taken once the transient has died out. The
servo model's rate limit and lag make the real amplitude, and with it the speed, collapse at
high frequency; ``ideal`` is eq 18 on the commanded angles (servos that follow exactly).
The servo's slew limit is calibrated on the paper's 3 Hz cap, not on this figure
(``wirefish_analysis.servo_calibration``), so the peak frequency is a prediction.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
import json
from pathlib import Path

import numpy as np
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.steady_state import steady_state_servo_angles
from wirefish_cpg.table1_gait import amplitude_scale_for, locked_speed_estimate, table1_locked_at
from wirefish_kinematics.geometry import FishGeometry
from wirefish_sim.servo_model import ServoParameters
from wirefish_sim.virtual_fish import SimConfig, VirtualFish
from wirefish_sim.virtual_fleet import VirtualFleet

SCALE_FREQUENCY_HZ = 3.0  # amplitudes are scaled once, with ideal servos, at this frequency
COMMAND_RATE_HZ = 200.0


@dataclass(frozen=True)
class SteadyRun:
    """Result of driving the virtual fish with one gait: mean speed and tail amplitude."""

    frequency_hz: float
    speed: float            # mean surge speed over the averaging window (m/s)
    tail_tip_amplitude: float  # half peak-to-peak of the simulated tail tip offset (m)
    ideal_speed: float      # eq 18 on the commanded angles (m/s)


def run_steady(params: CpgParameters, frequency_hz: float, geometry: FishGeometry,
               config: SimConfig | None = None, settle_s: float = 5.0,
               average_s: float = 2.0) -> SteadyRun:
    """
    Drive a virtual fish with the locked gait ``params`` and return its steady mean speed.

    Commands at 200 Hz (as cpg_node); ``settle_s`` for the transient (several surge time
    constants), then the mean over ``average_s`` rounded to whole tail-beat periods.
    """
    config = config or SimConfig(command_timeout_s=None, heartbeat_timeout_s=None)
    fish = VirtualFish(config, geometry, np.random.default_rng(0))
    dt = 1.0 / COMMAND_RATE_HZ
    periods = max(1, round(average_s * frequency_hz))
    steps_settle = round(settle_s / dt)
    steps_average = round(periods / frequency_hz / dt)
    times = np.arange(steps_settle + steps_average) * dt
    commands, _ = steady_state_servo_angles(params, times)
    speeds, tips = [], []
    for i, (servo_1, servo_2) in enumerate(commands.tolist()):
        fish.command(servo_1, servo_2)
        fish.step(dt)
        if i >= steps_settle:
            speeds.append(fish.state.speed)
            tips.append(fish.state.tail_tip_offset)
    ideal = locked_speed_estimate(params, geometry).speed
    return SteadyRun(frequency_hz, float(np.mean(speeds)), 0.5 * float(np.ptp(tips)), ideal)


def run_steady_school(gaits: Sequence[tuple[CpgParameters, float]], geometry: FishGeometry,
                      config: SimConfig | None = None, settle_s: float = 5.0,
                      average_s: float = 2.0) -> list[SteadyRun]:
    """
    Return ``run_steady`` of every (gait, frequency) of ``gaits``, swum as one school.

    One ``VirtualFleet`` (one physics vectorised over the fish) swims every gait at once, each
    fish with its own commands: a fish of a school swims as it would alone (to float rounding),
    so each result is ``run_steady``'s. Every fish runs as long as the longest run; a fish's
    mean and amplitude are over its own window, after which it swims on unobserved.
    """
    config = config or SimConfig(command_timeout_s=None, heartbeat_timeout_s=None)
    school = VirtualFleet([np.random.default_rng(0) for _ in gaits], config, geometry)
    dt = 1.0 / COMMAND_RATE_HZ
    steps_settle = round(settle_s / dt)
    windows = [round(max(1, round(average_s * f)) / f / dt) for _, f in gaits]
    total = steps_settle + max(windows)
    times = np.arange(total) * dt
    commands = np.stack([steady_state_servo_angles(params, times)[0] for params, _ in gaits])
    speeds = np.empty((len(gaits), total))
    tips = np.empty((len(gaits), total))
    for i in range(total):
        for fish, command in zip(school.fish, commands[:, i].tolist()):
            fish.command(*command)
        school.step(dt)
        speeds[:, i] = [fish.state.speed for fish in school.fish]
        tips[:, i] = [fish.state.tail_tip_offset for fish in school.fish]
    runs = []
    for f, ((params, frequency), window) in enumerate(zip(gaits, windows)):
        observed = slice(steps_settle, steps_settle + window)
        runs.append(SteadyRun(frequency, float(np.mean(speeds[f, observed])),
                              0.5 * float(np.ptp(tips[f, observed])),
                              locked_speed_estimate(params, geometry).speed))
    return runs


def speed_sweep(frequencies_hz: np.ndarray | None = None, tip_amplitude_m: float = 0.05,
                geometry: FishGeometry | None = None,
                config: SimConfig | None = None) -> list[SteadyRun]:
    """
    Return the steady runs at ``frequencies_hz`` at ``tip_amplitude_m`` (5 cm).

    Default frequencies: 1..10 Hz by 0.5 Hz, beyond the paper's 1..8 Hz so that the fall-off
    past the peak also shows with faster servos (``--servo-rate-limit 12`` peaks at 8.5 Hz).
    The frequencies swim as one school (``run_steady_school``: each run is ``run_steady``'s;
    the paper's 15 frequencies took 5.1 CPU s against 29.8 one by one, with equal results).
    """
    geometry = geometry or FishGeometry()
    if frequencies_hz is None:
        frequencies_hz = np.arange(1.0, 10.01, 0.5)
    scale = amplitude_scale_for(tip_amplitude_m, SCALE_FREQUENCY_HZ, geometry)
    return run_steady_school([(table1_locked_at(f, scale), f)
                              for f in np.asarray(frequencies_hz, dtype=float).tolist()],
                             geometry, config)


def peak_frequency(runs: list[SteadyRun]) -> float:
    """Return the frequency (Hz) of the fastest run."""
    return max(runs, key=lambda run: run.speed).frequency_hz


def write_png(runs: list[SteadyRun], path: Path) -> None:
    """Plot speed and tail amplitude against frequency (the shape of Fig 11) to ``path``."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    f = [r.frequency_hz for r in runs]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(f, [r.speed for r in runs], 'o-', label='virtual fish (servo model)')
    ax.plot(f, [r.ideal_speed for r in runs], '--', color='gray',
            label='eq 18, ideal servos')
    ax.axvline(peak_frequency(runs), color='C3', lw=0.8, ls=':',
               label=f'peak {peak_frequency(runs):g} Hz')
    ax.set_xlabel('tail-beat frequency (Hz)')
    ax.set_ylabel('steady swimming speed (m/s)')
    ax.set_title('Speed vs frequency at 5 cm tail-tip amplitude (cf. paper Fig 11)')
    twin = ax.twinx()
    twin.plot(f, [100.0 * r.tail_tip_amplitude for r in runs], 's:', color='C2', ms=4,
              label='simulated tail-tip amplitude')
    twin.set_ylabel('tail-tip half amplitude (cm)', color='C2')
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], loc='upper left', fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Run the sweep, write the PNG, print the numbers as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=Path('out/fig11.png'), help='PNG path')
    parser.add_argument('--amplitude', type=float, default=0.05, help='tail-tip amplitude (m)')
    parser.add_argument('--servo-rate-limit', type=float,
                        default=ServoParameters.rate_limit_rad_s,
                        help='servo slew limit (rad/s): where the speed peaks depends on it')
    args = parser.parse_args(argv)
    try:
        servo = ServoParameters(rate_limit_rad_s=args.servo_rate_limit)
    except ValueError as error:
        parser.error(str(error))
    config = SimConfig(command_timeout_s=None, heartbeat_timeout_s=None, servo=servo)
    runs = speed_sweep(tip_amplitude_m=args.amplitude, config=config)
    write_png(runs, args.out)
    print(json.dumps({'png': str(args.out), 'servo_rate_limit_rad_s': servo.rate_limit_rad_s,
                      'peak_hz': peak_frequency(runs), 'runs': [r.__dict__ for r in runs]},
                     indent=1))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
