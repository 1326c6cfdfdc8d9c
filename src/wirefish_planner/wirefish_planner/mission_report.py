"""
A mission's report from its ground truth (pure; matplotlib without a display).

The trajectory of ``sim/ground_truth`` as an x-y path with heading arrows, the speed and the
yaw rate against the mission's setpoints, and the closure error: the distance between where
the fish was when the first leg started and where it came to rest after the last.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import numpy as np
from wirefish_planner.mission_plan import Mission
from wirefish_planner.yaw_control import identify_turn_gain, steady_means

ARROW_EVERY_S = 1.0
SMOOTH_S = 1.0  # the ground truth beats with the tail: the plots also show a 1 s mean


@dataclass(frozen=True)
class Track:
    """Ground truth samples, time (s) from the first leg's start, odom frame (m, rad)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray


@dataclass(frozen=True)
class MissionSummary:
    """What the report prints: closure error (m), path length (m), per-leg means."""

    closure_error_m: float
    path_length_m: float
    legs: list[tuple[float, float, float, float]]  # (speed set, speed mean, rate set, mean)


def _at(track: Track, t: float) -> int:
    return min(len(track.t) - 1, int(np.searchsorted(track.t, t)))


def summarise(track: Track, mission: Mission, settle_s: float = 2.0) -> MissionSummary:
    """Return the closure error and each leg's mean speed and yaw rate after ``settle_s``."""
    if len(track.t) < 2:
        raise ValueError('no ground truth samples: was sim/ground_truth recorded?')
    start = _at(track, 0.0)
    closure = math.hypot(track.x[-1] - track.x[start], track.y[-1] - track.y[start])
    steps = np.hypot(np.diff(track.x[start:]), np.diff(track.y[start:]))
    legs = []
    for leg, begin in zip(mission.legs, mission.leg_starts()):
        window = (track.t >= begin + min(settle_s, 0.5 * leg.duration_s)) & \
            (track.t < begin + leg.duration_s)
        speed = float(track.speed[window].mean()) if window.any() else math.nan
        rate = float(track.yaw_rate[window].mean()) if window.any() else math.nan
        legs.append((leg.speed, speed, leg.yaw_rate, rate))
    return MissionSummary(float(closure), float(steps.sum()), legs)


def _smooth(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    if len(t) < 3:
        return values
    width = max(1, int(round(SMOOTH_S / float(np.median(np.diff(t))))))
    kernel = np.ones(width) / width
    return np.convolve(values, kernel, mode='same')


def plot_mission(track: Track, mission: Mission, summary: MissionSummary,
                 path: Path) -> Path:
    """Write the report PNG (path with heading arrows, speed, yaw rate) to ``path``."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt

    setpoints = [mission.command_at(float(t)) for t in track.t]
    speed_set = np.array([math.nan if c is None else c[0] for c in setpoints])
    rate_set = np.array([math.nan if c is None else c[1] for c in setpoints])
    fig = plt.figure(figsize=(12, 7))
    ax_path = fig.add_subplot(1, 2, 1)
    ax_speed = fig.add_subplot(2, 2, 2)
    ax_rate = fig.add_subplot(2, 2, 4, sharex=ax_speed)
    ax_path.plot(track.x, track.y, color='tab:blue', lw=1.2, label='ground truth')
    every = max(1, int(round(ARROW_EVERY_S / float(np.median(np.diff(track.t))))))
    ax_path.quiver(track.x[::every], track.y[::every], np.cos(track.yaw[::every]),
                   np.sin(track.yaw[::every]), angles='xy', scale_units='xy', scale=8.0,
                   width=0.004, color='tab:orange', label='heading')
    start = _at(track, 0.0)
    ax_path.plot(track.x[start], track.y[start], 'go', label='start (first leg)')
    ax_path.plot(track.x[-1], track.y[-1], 'rs', label='rest after the last leg')
    ax_path.set_title(f'{mission.name}: closure error {summary.closure_error_m:.3f} m '
                      f'over {summary.path_length_m:.2f} m')
    ax_path.set_xlabel('x (m, odom)')
    ax_path.set_ylabel('y (m, odom)')
    ax_path.set_aspect('equal', adjustable='datalim')
    ax_path.grid(True, alpha=0.3)
    ax_path.legend(loc='best', fontsize=8)
    for ax, values, target, label in ((ax_speed, track.speed, speed_set, 'speed (m/s)'),
                                      (ax_rate, track.yaw_rate, rate_set, 'yaw rate (rad/s)')):
        ax.plot(track.t, values, color='0.75', lw=0.6, label='ground truth')
        ax.plot(track.t, _smooth(track.t, values), color='tab:blue', lw=1.2,
                label=f'{SMOOTH_S:g} s mean')
        ax.plot(track.t, target, 'k--', lw=1.0, label='cmd_vel setpoint')
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(loc='best', fontsize=8)
    ax_rate.set_xlabel('time from the first leg (s)')
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def summary_text(mission: Mission, summary: MissionSummary) -> str:
    """Return the printed summary: closure error and a line per leg."""
    lines = [f'mission {mission.name}: {len(mission.legs)} legs, {mission.duration_s:.1f} s; '
             f'closure error {summary.closure_error_m:.3f} m over a '
             f'{summary.path_length_m:.2f} m path']
    for index, (speed_set, speed, rate_set, rate) in enumerate(summary.legs, start=1):
        lines.append(f'  leg {index:>2}: speed {speed_set:.3f} -> {speed:.3f} m/s, yaw rate '
                     f'{rate_set:+.3f} -> {rate:+.3f} rad/s')
    return '\n'.join(lines)


def turn_gain_text(states: list) -> str:
    """Return the turn gain identified from recorded planner_state (or why it cannot be)."""
    rows = [(t, m.predicted_speed, m.offset, m.yaw_rate_measured) for t, m in states
            if m.mode in ('turn', 'hold', 'straight')]
    if len(rows) < 3:
        return 'turn gain: not identified (no planner_state of a closed-loop run recorded)'
    data = np.array(rows)
    try:
        gain, bias = identify_turn_gain(*steady_means(*data.T))
    except ValueError as error:
        return f'turn gain: not identified: {error}'
    return (f'turn gain identified from this run (r = k U b + d, steady 1 s means): '
            f'k = {gain:.2f} rad/s per rad per m/s (planner parameter turn_gain), '
            f'd = {bias:+.4f} rad/s (a current, or the gyro bias)')
