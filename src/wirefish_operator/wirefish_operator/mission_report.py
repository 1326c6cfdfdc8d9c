# SPDX-License-Identifier: Apache-2.0
"""
A mission's report from its ground truth (pure; matplotlib without a display).

The trajectory of ``sim/ground_truth`` as an x-y path with heading arrows, the speed and the
yaw rate against the mission's setpoints, and the closure error: the distance between where
the fish was when the first leg started and where it came to rest after the last. The path is
drawn in the frame of the first leg's start (origin there, x along its heading): the
odometry's own origin is wherever the virtual fish was started, maybe many runs ago. The
rest marker is where the fish's 1 s mean speed first stayed below ``REST_SPEED`` after the
last leg; a fish still swimming when the recording ended is said so, and marked as that.

The turn gain k of r = k U b + d is identified from per-leg means of the recorded
planner_state (after each leg's settling), and judged before it is called usable: enough
legs, a fit that explains the yaw rate (R^2), a small standard error, and the sign of the
planner's own ``turn_gain``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path

import numpy as np
from wirefish_common.plotting import legend_beside, moving_mean
from wirefish_operator.mission_plan import Mission
from wirefish_planner.planner_core import PlannerMode
from wirefish_planner.yaw_control import identify_turn_gain

ARROW_EVERY_S = 1.0
SMOOTH_S = 1.0  # the ground truth beats with the tail: the plots also show a 1 s mean
REST_SPEED = 0.02  # m/s: below this (1 s mean) the fish has come to rest
# A turn gain is usable when fitted over this many legs, with this R^2 and relative error.
MIN_GAIN_LEGS = 4
MIN_GAIN_R_SQUARED = 0.9
MAX_GAIN_RELATIVE_ERROR = 0.2
CLOSED_LOOP_MODES = (PlannerMode.TURN, PlannerMode.HOLD, PlannerMode.STRAIGHT)


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
    rested: bool = True  # False: still swimming when the recording ended
    end_speed: float = 0.0  # the 1 s mean speed (m/s) where the rest marker is


def _at(track: Track, t: float) -> int:
    return min(len(track.t) - 1, int(np.searchsorted(track.t, t)))


def from_start(track: Track) -> Track:
    """Return ``track`` in the frame of the first leg's start: there (0, 0), heading +x."""
    if len(track.t) == 0:
        return track
    start = _at(track, 0.0)
    dx, dy = track.x - track.x[start], track.y - track.y[start]
    cos, sin = math.cos(-track.yaw[start]), math.sin(-track.yaw[start])
    yaw = np.arctan2(np.sin(track.yaw - track.yaw[start]), np.cos(track.yaw - track.yaw[start]))
    return Track(track.t, cos * dx - sin * dy, sin * dx + cos * dy, yaw, track.speed,
                 track.yaw_rate)


def rest_index(track: Track, mission: Mission) -> tuple[int, bool]:
    """
    Return (index of where the fish came to rest after the last leg, whether it did).

    The first sample after the last leg from which the 1 s mean speed stays below REST_SPEED;
    (the last sample, False) when the recording ends with the fish still swimming.
    """
    smooth = np.abs(_smooth(track.t, track.speed))
    after = np.nonzero(track.t >= mission.duration_s)[0]
    moving = [i for i in after if smooth[i] >= REST_SPEED]
    if not len(after):
        return len(track.t) - 1, False
    if not moving:
        return int(after[0]), True
    last_moving = int(moving[-1])
    if last_moving >= len(track.t) - 1 or track.t[-1] - track.t[last_moving] < SMOOTH_S:
        return len(track.t) - 1, False
    return last_moving + 1, True


def summarise(track: Track, mission: Mission, settle_s: float = 2.0) -> MissionSummary:
    """Return the closure error and each leg's mean speed and yaw rate after ``settle_s``."""
    if len(track.t) < 2:
        raise ValueError('no ground truth samples: was sim/ground_truth recorded?')
    start = _at(track, 0.0)
    rest, rested = rest_index(track, mission)
    closure = math.hypot(track.x[rest] - track.x[start], track.y[rest] - track.y[start])
    steps = np.hypot(np.diff(track.x[start:rest + 1]), np.diff(track.y[start:rest + 1]))
    legs = []
    for leg, begin in zip(mission.legs, mission.leg_starts()):
        window = (track.t >= begin + min(settle_s, 0.5 * leg.duration_s)) & \
            (track.t < begin + leg.duration_s)
        speed = float(track.speed[window].mean()) if window.any() else math.nan
        rate = float(track.yaw_rate[window].mean()) if window.any() else math.nan
        legs.append((leg.speed, speed, leg.yaw_rate, rate))
    return MissionSummary(float(closure), float(steps.sum()), legs, rested,
                          float(abs(_smooth(track.t, track.speed)[rest])))


def _smooth(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Return the SMOOTH_S moving mean of ``values`` (over what there is, at the ends)."""
    return moving_mean(t, values, SMOOTH_S)


def plot_mission(track: Track, mission: Mission, summary: MissionSummary,
                 path: Path) -> Path:
    """Write the report PNG (path with heading arrows, speed, yaw rate) to ``path``."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt

    track = from_start(track)

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
    rest, _ = rest_index(track, mission)
    ax_path.plot(track.x[start], track.y[start], 'go', label='start (first leg)')
    ax_path.plot(track.x[rest], track.y[rest], 'rs',
                 label='rest after the last leg' if summary.rested
                 else f'end of recording, still at {summary.end_speed:.2f} m/s')
    ax_path.set_title(f'{mission.name}: closure error {summary.closure_error_m:.3f} m '
                      f'over {summary.path_length_m:.2f} m')
    ax_path.set_xlabel("x (m, from the first leg's start, along its heading)")
    ax_path.set_ylabel('y (m, to its left)')
    ax_path.set_aspect('equal', adjustable='datalim')
    ax_path.grid(True, alpha=0.3)
    legend_beside(ax_path)
    for ax, values, target, label in ((ax_speed, track.speed, speed_set, 'speed (m/s)'),
                                      (ax_rate, track.yaw_rate, rate_set, 'yaw rate (rad/s)')):
        ax.plot(track.t, values, color='0.75', lw=0.6, label='ground truth')
        ax.plot(track.t, _smooth(track.t, values), color='tab:blue', lw=1.2,
                label=f'{SMOOTH_S:g} s mean')
        ax.plot(track.t, target, 'k--', lw=1.0, label='cmd_vel setpoint')
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        legend_beside(ax)
    ax_rate.set_xlabel('time from the first leg (s)')
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches='tight')  # the legends sit beside the axes
    plt.close(fig)
    return path


def summary_text(mission: Mission, summary: MissionSummary) -> str:
    """Return the printed summary: closure error and a line per leg."""
    lines = [f'mission {mission.name}: {len(mission.legs)} legs, {mission.duration_s:.1f} s; '
             f'closure error {summary.closure_error_m:.3f} m over a '
             f'{summary.path_length_m:.2f} m path'
             + ('' if summary.rested else f' (the fish still swam {summary.end_speed:.2f} m/s '
                'when the recording ended: measured to there)')]
    for index, (speed_set, speed, rate_set, rate) in enumerate(summary.legs, start=1):
        lines.append(f'  leg {index:>2}: speed {speed_set:.3f} -> {speed:.3f} m/s, yaw rate '
                     f'{rate_set:+.3f} -> {rate:+.3f} rad/s')
    return '\n'.join(lines)


@dataclass(frozen=True)
class TurnGainFit:
    """r = k U b + d over per-leg means: k, d, R^2, the standard error of k, legs used."""

    gain: float
    bias: float
    r_squared: float
    gain_stderr: float
    legs: int


def leg_means(states: list, mission: Mission, settle_s: float = 2.0
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return per-leg means of U, b and r from (t, planner_state), t from the first leg's start.

    Each leg's samples after ``settle_s`` (at most half the leg) in a closed-loop mode count.
    """
    rows = []
    for leg, begin in zip(mission.legs, mission.leg_starts()):
        inside = [(m.predicted_speed, m.offset, m.yaw_rate_measured) for t, m in states
                  if begin + min(settle_s, 0.5 * leg.duration_s) <= t < begin + leg.duration_s
                  and m.mode in CLOSED_LOOP_MODES]
        if inside:
            rows.append(np.mean(np.array(inside, dtype=float), axis=0))
    if not rows:
        return np.array([]), np.array([]), np.array([])
    u, b, r = np.array(rows).T
    return u, b, r


def fit_turn_gain(speed: np.ndarray, offset: np.ndarray, yaw_rate: np.ndarray) -> TurnGainFit:
    """Return the fit of r = k U b + d with its quality; ValueError when U b hardly varies."""
    gain, bias = identify_turn_gain(speed, offset, yaw_rate)
    x, r = np.asarray(speed) * np.asarray(offset), np.asarray(yaw_rate)
    residual = r - (gain * x + bias)
    total = float(np.sum((r - r.mean()) ** 2))
    r_squared = 1.0 - float(np.sum(residual ** 2)) / total if total > 0.0 else 0.0
    dof = len(x) - 2
    spread = float(np.sum((x - x.mean()) ** 2))
    stderr = (math.sqrt(float(np.sum(residual ** 2)) / dof / spread)
              if dof > 0 and spread > 0.0 else math.inf)
    return TurnGainFit(gain, bias, r_squared, stderr, len(x))


def turn_gain_problem(fit: TurnGainFit, configured: float | None) -> str | None:
    """Return why an identified turn gain is not usable, or None when it is."""
    if fit.legs < MIN_GAIN_LEGS:
        return f'only {fit.legs} legs (at least {MIN_GAIN_LEGS})'
    if fit.r_squared < MIN_GAIN_R_SQUARED:
        return f'the fit explains little of the yaw rate (R^2 {fit.r_squared:.2f})'
    if not abs(fit.gain_stderr) <= MAX_GAIN_RELATIVE_ERROR * abs(fit.gain):
        return f'its standard error is {fit.gain_stderr:.2f}'
    if configured is not None and configured * fit.gain <= 0.0:
        return f"its sign is not that of the planner's turn_gain ({configured:.2f})"
    return None


def turn_gain_text(states: list, mission: Mission, configured: float | None = None) -> str:
    """
    Return the turn gain identified from recorded planner_state, judged (or why there is none).

    ``states`` are (t from the first leg's start, planner_state); ``configured`` is the
    planner's own ``turn_gain`` (None when it could not be read).
    """
    planner = '' if configured is None else f"; the planner's turn_gain is {configured:.2f}"
    try:
        fit = fit_turn_gain(*leg_means(states, mission))
    except ValueError as error:
        return f'turn gain: not identified: {error}'
    figures = (f'k = {fit.gain:.2f} +- {fit.gain_stderr:.2f} rad/s per rad per m/s, '
               f'd = {fit.bias:+.4f} rad/s (R^2 {fit.r_squared:.2f} over {fit.legs} legs'
               f'{planner})')
    problem = turn_gain_problem(fit, configured)
    if problem is not None:
        return f'turn gain: NOT usable from this run ({problem}): {figures}'
    return (f'turn gain identified from this run (r = k U b + d, per-leg means): {figures}; '
            'planner parameter turn_gain')
