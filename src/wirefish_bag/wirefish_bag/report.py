# SPDX-License-Identifier: Apache-2.0
"""
Plots and a summary table from a recorded run (`wirefish report` writes them).

PNGs: the CPG outputs, a body-wave snapshot against the desired wave, the estimated speed
against the virtual fish's ground truth, the IMU attitude. The table: per topic, the message
count, the mean rate, the longest gap between header stamps and the drops (messages that the
stamps' span at the median period calls for but that are missing), and the bridge's link
counters from /diagnostics.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wirefish_bag.bagfile import read_bag
from wirefish_common.plotting import legend_beside, moving_mean

SPEED_MEAN_S = 1.0  # the ground truth's mean in the speed plot: a few tail beats


@dataclass(frozen=True)
class TopicStats:
    """Counts and timing of one topic in a bag."""

    topic: str
    type_name: str
    count: int
    rate_hz: float
    period_s: float
    max_gap_s: float
    drops: int


def topic_stats(topic: str, type_name: str, stamps_s: np.ndarray) -> TopicStats:
    """
    Summarise one topic from its message stamps (s), header stamps where it has them.

    Drops are the messages that the stamps' span at the topic's period calls for but that are
    missing. The period is the median over windows of 20 intervals, so arrival jitter (a late
    sample, then an early one) averages out and only real gaps count. Topics without a steady
    period (events such as speed_estimate) get no drop count (-1).
    """
    count = len(stamps_s)
    if count < 2:
        return TopicStats(topic, type_name, count, 0.0, float('nan'), float('nan'), 0)
    stamps_s = np.sort(stamps_s)
    periods = np.diff(stamps_s)
    span = float(stamps_s[-1] - stamps_s[0])
    window = min(20, count - 1)
    period = float(np.median((stamps_s[window:] - stamps_s[:-window]) / window))
    shortest = max(float(np.percentile(periods, 10)), 1e-3 * period)
    steady = period > 0 and np.percentile(periods, 90) <= 10 * shortest
    drops = max(0, int(round(span / period)) + 1 - count) if steady else -1
    return TopicStats(topic, type_name, count, (count - 1) / span if span > 0 else 0.0,
                      period, float(periods.max()), drops)


def _series(bag, topic: str) -> list:
    return bag.messages.get(topic, [])


def _stamp(msg) -> float:
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def write_report(bag_path: Path, out_dir: Path) -> list[TopicStats]:
    """Write the PNGs and summary.txt of ``bag_path`` into ``out_dir``; return the stats."""
    from wirefish_bag.bag_storage import recording_custom_data
    from wirefish_bag.sequence_gaps import loss_line

    bag = read_bag(bag_path)
    out_dir.mkdir(parents=True, exist_ok=True)
    stats = []
    for topic, type_name in sorted(bag.types.items()):
        msgs = _series(bag, topic)
        if msgs and hasattr(msgs[0][1], 'header'):
            stamps = np.array([_stamp(m) for _, m in msgs])
        else:
            stamps = np.array([t for t, _ in msgs])
        stats.append(topic_stats(topic, type_name, stamps))
    t0 = bag.start_s

    def find(suffix: str) -> str | None:
        return next((t for t in bag.types if t.endswith(suffix)), None)

    servo = find('/servo_cmd')
    if servo:
        msgs = _series(bag, servo)
        t = np.array([_stamp(m) for _, m in msgs]) - t0
        _save(cpg_figure(t, np.array([list(m.position) for _, m in msgs])),
              out_dir / 'cpg_outputs.png')
    wave = find('/body_wave')
    if wave and _series(bag, wave):
        _save(body_wave_figure(_series(bag, wave)[-1][1]), out_dir / 'body_wave.png')
    speed = find('/speed_estimate')
    truth = find('/sim/ground_truth')
    if speed or truth:
        estimate = [(_stamp(m) - t0, m.speed) for _, m in _series(bag, speed)] if speed else []
        fish = ([(_stamp(m) - t0, m.twist.twist.linear.x) for _, m in _series(bag, truth)]
                if truth else [])
        _save(speed_figure(estimate, fish), out_dir / 'speed.png')
    attitude = find('/attitude')
    if attitude:
        msgs = _series(bag, attitude)
        t = np.array([_stamp(m) for _, m in msgs]) - t0
        angles = np.array([(m.vector.x, m.vector.y, m.vector.z) for _, m in msgs])
        _save(attitude_figure(t, angles), out_dir / 'attitude.png')
    # What the recorder itself counted: messages missing from the publishers' sequences.
    loss = loss_line(recording_custom_data(bag_path))
    (out_dir / 'summary.txt').write_text(summary_table(stats, bag) + '\n' + loss + '\n')
    return stats


def _pyplot():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path: Path) -> None:
    fig.savefig(path, dpi=110, bbox_inches='tight')  # the legends sit beside the axes
    _pyplot().close(fig)


def cpg_figure(t: np.ndarray, positions: np.ndarray):
    """Return the CPG outputs (servo_cmd) over time, one curve per servo, legend beside."""
    fig, ax = _pyplot().subplots(figsize=(8, 3.5))
    for i in range(positions.shape[1] if positions.ndim == 2 else 0):
        ax.plot(t, positions[:, i], lw=0.8, label=f'servo_{i + 1}')
    ax.set(xlabel='time (s)', ylabel='angle (rad)', title='CPG outputs (servo_cmd)')
    legend_beside(ax)
    fig.tight_layout()
    return fig


def body_wave_figure(msg):
    """Return the last body-wave snapshot with the desired wave, legend beside."""
    fig, ax = _pyplot().subplots(figsize=(7, 3.5))
    ax.plot(msg.x, msg.y, '-', label='tail (kinematics)')
    if len(msg.y_desired):
        ax.plot(msg.x, msg.y_desired, ':', label='desired (eq 23)')
    ax.set(xlabel='x in tail_base (m)', ylabel='y (m)', title='Body wave, last snapshot')
    ax.axis('equal')
    legend_beside(ax)
    fig.tight_layout()
    return fig


def speed_figure(estimate: list[tuple[float, float]], truth: list[tuple[float, float]]):
    """
    Return the speed estimate (one a tail beat) beside the ground truth's mean.

    The ground truth beats with the tail: drawn raw in light grey, and as its mean over one
    second, which compares with an estimate that is a mean over a beat.
    """
    fig, ax = _pyplot().subplots(figsize=(8, 3.5))
    if truth:
        t, u = np.array(truth).T
        ax.plot(t, u, color='0.8', lw=0.6, label='virtual fish, raw (ground truth)')
        ax.plot(t, moving_mean(t, u, SPEED_MEAN_S), color='tab:blue', lw=1.4,
                label=f'virtual fish, {SPEED_MEAN_S:g} s mean')
    if estimate:
        t, u = np.array(estimate).T
        ax.plot(t, u, '.-', color='tab:orange', label='Lighthill estimate (eq 18, per beat)')
    ax.set(xlabel='time (s)', ylabel='surge speed (m/s)', title='Swimming speed')
    legend_beside(ax)
    fig.tight_layout()
    return fig


def attitude_figure(t: np.ndarray, angles: np.ndarray):
    """
    Return roll, pitch and yaw (deg) each on its own axis, yaw unwrapped.

    One axis for all three let a yaw of -140 deg flatten roll and pitch to a line; unwrapped,
    a yaw through +-180 deg is a turn, not a jump.
    """
    fig, axes = _pyplot().subplots(3, 1, figsize=(8, 6), sharex=True)
    values = np.degrees(np.array(angles, dtype=float).reshape(-1, 3))
    if len(values):
        values[:, 2] = np.degrees(np.unwrap(np.radians(values[:, 2])))
    for ax, column, name in zip(axes, range(3), ('roll', 'pitch', 'yaw (unwrapped)')):
        ax.plot(t, values[:, column], lw=0.8)
        ax.set_ylabel(f'{name} (deg)')
        ax.grid(True, alpha=0.3)
    axes[0].set_title('IMU attitude')
    axes[-1].set_xlabel('time (s)')
    fig.tight_layout()
    return fig


def summary_table(stats: list[TopicStats], bag) -> str:
    """Return the per-topic table and the bridge's last diagnostic counters as text."""
    lines = [f'bag: {bag.path}  duration {bag.duration_s:.1f} s',
             f'{"topic":<34} {"count":>7} {"rate Hz":>8} {"max gap s":>9} {"drops":>6}']
    for s in stats:
        drops = '—' if s.drops < 0 else str(s.drops)
        lines.append(f'{s.topic:<34} {s.count:>7} {s.rate_hz:>8.1f} {s.max_gap_s:>9.3f} '
                     f'{drops:>6}')
    diagnostics = _series(bag, '/diagnostics')
    if diagnostics:
        lines.append('last /diagnostics:')
        for status in diagnostics[-1][1].status:
            values = ', '.join(f'{kv.key}={kv.value}' for kv in status.values)
            lines.append(f'  {status.name}: {status.message} ({values})')
    return '\n'.join(lines)
