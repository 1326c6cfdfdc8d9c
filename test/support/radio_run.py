# SPDX-License-Identifier: Apache-2.0
"""
One drive of the whole graph behind the radio model: `wirefish up --radio PRESET` by cmd_vel.

``drive`` starts the graph (``e2e_utils.start_graph``), drives it by cmd_vel through a schedule
and records, on the wall clock (``time.monotonic``, the clock the radio relay stamps its cuts
with): the ground truth's speed, the board's servo_state, the bridge's /diagnostics values and
cpg_params; then stops the graph (no process left) and reads the relay's counters.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
import json
import math
import os
from pathlib import Path
import time

from diagnostic_msgs.msg import DiagnosticArray
from e2e_utils import descendants, start_launcher
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import qos_profile_sensor_data
from ros_utils import stop_process
from sensor_msgs.msg import JointState
from wirefish_common.qos import LATCHED, RELIABLE
from wirefish_msgs.msg import CpgParams

# The commands of every drive: (start s, forward m/s, yaw rate rad/s), held to the next start.
# 10 s a command: the surge settles in ~6 s (time constant ~1.5 s), and each speed is judged
# from 5 s after its command.
SCHEDULE = ((0.0, 0.15, 0.0), (10.0, 0.25, 0.0), (20.0, 0.2, 0.2), (30.0, 0.2, 0.0))
DRIVE_S = 40.0
CMD_RATE_HZ = 10.0


def domain_id() -> int:
    """Return the ROS domain of a module's graphs (one module at a time per worker)."""
    return int(os.environ.get('WIREFISH_TEST_DOMAIN_BASE', '21')) + 19


def command_at(t: float) -> tuple[float, float]:
    """Return (forward m/s, yaw rate rad/s) of SCHEDULE at ``t`` s into the drive."""
    current = SCHEDULE[0]
    for step in SCHEDULE:
        if t >= step[0]:
            current = step
    return current[1], current[2]


@dataclass
class Drive:
    """What one drive recorded (times: time.monotonic)."""

    preset: str
    drive_mode: str
    started: float = 0.0
    truth: list[tuple[float, float]] = field(default_factory=list)           # t, speed
    servo: list[tuple[float, float, float]] = field(default_factory=list)    # t, s1, s2
    diagnostics: list[tuple[float, int, str, dict]] = field(default_factory=list)
    cpg_params: list[tuple[float, CpgParams]] = field(default_factory=list)
    radio: dict = field(default_factory=dict)
    cuts: list[tuple[float, float]] = field(default_factory=list)
    log: str = ''

    def mean_speed(self, start_s: float, end_s: float) -> float:
        """Return the mean ground-truth speed between ``start_s`` and ``end_s`` of the drive."""
        values = [v for t, v in self.truth if start_s <= t - self.started < end_s]
        return float(np.mean(values)) if values else math.nan

    def at_end_of_drive(self, key: str) -> str:
        """Return the bridge's last /diagnostics value ``key`` of the drive (before any cut)."""
        values = [v for t, v in self.bridge_values(key) if t <= self.started + DRIVE_S]
        assert values, f'no {key} in the bridge diagnostics'
        return values[-1]

    def bridge_values(self, key: str) -> list[tuple[float, str]]:
        """Return (t, value) of one /diagnostics value of the bridge, in order."""
        return [(t, values[key]) for t, _, _, values in self.diagnostics if key in values]


class _Probe:
    def __init__(self, context: Context, namespace: str, record: Drive) -> None:
        self.node = rclpy.create_node('radio_probe', namespace=namespace, context=context)
        self.record = record
        node = self.node
        node.create_subscription(Odometry, 'sim/ground_truth', self._truth, RELIABLE)
        node.create_subscription(JointState, 'servo_state', self._servo, qos_profile_sensor_data)
        node.create_subscription(DiagnosticArray, '/diagnostics', self._diagnostics, RELIABLE)
        node.create_subscription(CpgParams, 'cpg_params', self._params, LATCHED)
        self.cmd = node.create_publisher(Twist, 'cmd_vel', RELIABLE)
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(node)

    def _truth(self, msg: Odometry) -> None:
        self.record.truth.append((time.monotonic(), msg.twist.twist.linear.x))

    def _servo(self, msg: JointState) -> None:
        self.record.servo.append((time.monotonic(), msg.position[0], msg.position[1]))

    def _diagnostics(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            if 'serial link' in status.name:
                self.record.diagnostics.append(
                    (time.monotonic(), status.level[0], status.message,
                     {kv.key: kv.value for kv in status.values}))

    def _params(self, msg: CpgParams) -> None:
        self.record.cpg_params.append((time.monotonic(), msg))

    def command(self, forward: float, yaw_rate: float) -> None:
        msg = Twist()
        msg.linear.x, msg.angular.z = forward, yaw_rate
        self.cmd.publish(msg)

    def spin_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and not predicate():
            self.executor.spin_once(timeout_sec=0.05)
        return predicate()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


def _run_dir(out: Path) -> Path:
    runs = sorted(out.glob('run_*'))
    assert runs, f'no run directory in {out}'
    return runs[-1]


def drive(out: Path, preset: str, *, drive_mode: str | None = None, drive_s: float = DRIVE_S,
          cut_s: float = 0.0, after_cut_s: float = 0.0, qemu: bool = False) -> Drive:
    """
    Start `wirefish up --sim --radio preset`, drive ``drive_s`` by SCHEDULE, stop; return it.

    ``cut_s`` > 0: then a radio cut that long with the last command held, and ``after_cut_s``
    of driving after it. ``qemu``: the ARM build in QEMU instead of the virtual fish (no
    ground truth: the drive starts once the board's servo_state arrives).
    """
    options = ['--radio', preset] + (['--drive-mode', drive_mode] if drive_mode else [])
    namespace = f'/radio_{preset}_{drive_mode or "road"}{"_qemu" if qemu else ""}'
    record = Drive(preset, drive_mode or 'road')
    graph = start_launcher(domain_id(), out, ['--fish', 'qemu'] if qemu else ['--sim'],
                           *options, namespace=namespace, timeout_s=90.0)
    children = descendants(graph.launcher.pid)
    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    probe = _Probe(context, namespace, record)
    try:
        source = record.servo if qemu else record.truth
        # The drive starts on a configured link: until LINK_CONFIG reaches it, a board floods
        # a narrow radio with its boot defaults (100 Hz of full telemetry); in gait mode, on a
        # board that runs its gait.
        waited_from = time.monotonic()
        assert probe.spin_until(lambda: bool(source) and _ready_to_drive(record), 60.0), \
            (f'within 60 s: {len(source)} samples of ground truth (servo_state on QEMU); the '
             f"bridge's last link values: {_last_link_values(record)}")
        record.started = time.monotonic()
        print(f'{preset} {record.drive_mode}: ready to drive (ground truth, the link '
              f'configured, a gait on the board in gait mode) {record.started - waited_from:.1f} '
              's after `wirefish up` ran')
        next_cmd = record.started
        total = drive_s + cut_s + after_cut_s
        control = _run_dir(out) / 'radio-control'
        cut_asked = False
        while (now := time.monotonic()) < record.started + total:
            if now >= next_cmd:
                probe.command(*command_at(min(now - record.started, drive_s - 0.01)))
                next_cmd += 1.0 / CMD_RATE_HZ
            if cut_s > 0.0 and not cut_asked and now >= record.started + drive_s:
                control.write_text(f'cut {cut_s}\n')
                cut_asked = True
            probe.executor.spin_once(timeout_sec=0.01)
    finally:
        probe.close()
        rclpy.try_shutdown(context=context)
        stop_process(graph.launcher, timeout_s=15.0)
        for child in children:
            if child.is_running():
                child.kill()
        record.log = graph.launcher.stdout.read()
        graph.launcher.stdout.close()
    radio = _run_dir(out) / 'radio.json'
    record.radio = json.loads(radio.read_text())
    record.cuts = [tuple(cut) for cut in record.radio['cuts']]
    return record


def _last_link_values(record: Drive) -> dict[str, str] | str:
    """Return the bridge's newest serial-link diagnostics values, or why there are none."""
    if not record.diagnostics:
        return 'no /diagnostics of the serial link'
    _, level, message, values = record.diagnostics[-1]
    return {'level': str(level), 'message': message, **values}


def _ready_to_drive(record: Drive) -> bool:
    """
    Return whether the bridge's newest diagnostics say the fish runs the wanted link.

    In gait mode also that the board's telemetry says it runs a gait (a non-zero gait id):
    between the link's ACK and the first GAIT's arrival the board is still in stream mode.
    """
    if not record.diagnostics:
        return False
    values = record.diagnostics[-1][3]
    if values.get('link_configured') != 'True':
        return False
    return values.get('drive_mode') != 'gait' or values.get('board_gait_id', '0') != '0'


def describe_link(record: Drive) -> str:
    """Return the link's figures of a drive: use per direction, losses."""
    radio = record.radio
    return (f'{record.preset} {record.drive_mode}: load to fish {radio["load_to_fish"]:.1%}, '
            f'to host {radio["load_to_host"]:.1%} of {radio["capacity_bytes_s"]:.0f} B/s, air '
            f'time {radio["use_to_fish"]:.1%} and {radio["use_to_host"]:.1%}, over '
            f'{radio["elapsed_s"]:.0f} s; packets lost '
            f'{radio["to_fish"]["packets_lost"]}/{radio["to_fish"]["packets_sent"]} to fish, '
            f'{radio["to_host"]["packets_lost"]}/{radio["to_host"]["packets_sent"]} to host; '
            f'frames refused by the UART {radio["to_fish"]["frames_refused"]} to fish, '
            f'{radio["to_host"]["frames_refused"]} to host; bytes overflowed '
            f'{radio["to_fish"]["bytes_overflowed"]}/{radio["to_host"]["bytes_overflowed"]}')


@dataclass(frozen=True)
class BoardFrame:
    """One telemetry of the fish, as it left the board (before the radio)."""

    t: float            # when the relay read it (time.monotonic)
    board_ms: int
    servo: tuple[float, float]
    status: int
    gait_id: int


def board_frames(out: Path) -> list[BoardFrame]:
    """Return the telemetry the fish sent during the drive (the relay's tap), in order."""
    from wirefish_bridge.codec import StreamDecoder
    from wirefish_bridge.protocol import telemetry_of
    from wirefish_sim.radio_relay import read_tap

    decoder = StreamDecoder()
    frames = []
    for t, data in read_tap(_run_dir(out) / 'radio-fish.tap'):
        for frame in decoder.feed(data):
            telemetry = telemetry_of(frame.message)
            if telemetry is not None:
                frames.append(BoardFrame(t, telemetry.board_time_ms,
                                         (telemetry.servo_1, telemetry.servo_2),
                                         int(telemetry.status), telemetry.gait_id))
    return frames


# The oscillator's smooth bound on the board's servo angles: between two telemetry frames dt
# apart the angle moves at most v_max dt (the mean value theorem), v_max being the oscillator's
# fastest motion, R 2 pi f for the largest amplitude and frequency of the drive's gaits, with 10 %
# for the couplings' phase pull and 0.5 rad/s for the amplitude and offset converging through
# alpha. Measured here: 5.5 rad/s the fastest chord, 6.7 rad/s the bound; the servo's own slew
# (9.1 rad/s, a snap to neutral) exceeds it.
PHASE_MARGIN = 1.1
CONVERGENCE_RAD_S = 0.5


def smooth_bound(record: Drive) -> float:
    """Return the oscillator's fastest motion over the drive (rad/s): the smooth bound."""
    params = [p for _, p in record.cpg_params]
    assert params, 'no cpg_params heard'
    speed = max(2 * math.pi * p.frequency_hz * max(p.amplitude) for p in params)
    return PHASE_MARGIN * speed + CONVERGENCE_RAD_S


def worst_step(frames: list[BoardFrame], speed: float) -> float:
    """Return the largest excess of a change between successive frames over ``speed`` dt."""
    worst = -math.inf
    for a, b in zip(frames, frames[1:]):
        dt = (b.board_ms - a.board_ms) / 1000.0
        if not 0.0 < dt <= 0.25:
            continue
        step = max(abs(b.servo[0] - a.servo[0]), abs(b.servo[1] - a.servo[1]))
        worst = max(worst, step - speed * dt)
    return worst


@dataclass(frozen=True)
class CutFigures:
    """What a radio cut did, from the board's frames and the bridge's records."""

    start: float
    end: float
    coasting_after_s: float      # from the cut's start to the first COASTING frame
    # From the first COASTING to the first RESTING frame on the board's own clock (board_ms): the
    # coast is the board's timer; the relay's read times add how late the host read each frame
    # (by them, a run pinned to one core measured a 3 s coast as 3.37 s).
    coast_s: float
    rest_amplitude: float        # largest |servo| of the last RESTING frames before the end
    link_back_s: float           # from the cut's end to the first servo_state at the bridge
    gait_back_s: float           # from the cut's end to the board running the current gait

    def line(self) -> str:
        """Return the figures as one printable line."""
        return (f'cut {self.start:.2f} .. {self.end:.2f}: COASTING {self.coasting_after_s:.2f} s '
                f'after its start, RESTING {self.coast_s:.2f} s later; servo within '
                f'{self.rest_amplitude:.4f} rad of neutral at its end; telemetry back '
                f'{self.link_back_s:.2f} s after it, the current gait running again '
                f'{self.gait_back_s:.2f} s after it')


def cut_figures(record: Drive, board: list[BoardFrame]) -> CutFigures:
    """Return the figures of the drive's one radio cut."""
    from wirefish_bridge.protocol import Status

    assert len(record.cuts) == 1, record.cuts
    start, end = record.cuts[0]
    coasting = [f for f in board if f.t >= start and f.status & Status.COASTING]
    resting = [f for f in board if f.t >= start and f.status & Status.RESTING]
    assert coasting and resting, 'the board never coasted or rested during the cut'
    rested = [f for f in resting if f.t <= end]
    amplitude = max(max(abs(v) for v in f.servo) for f in rested[-5:])
    after = [t for t, *_ in record.servo if t > end]
    # The gait the bridge had when the cut ended (its /diagnostics at 1 Hz: the newest before
    # the end), or a newer one the planner chose since: ids only grow within a drive.
    current = max(int(v) for t, v in record.bridge_values('gait_id') if t <= end)
    again = [f.t for f in board if f.t > end and f.gait_id >= current
             and not f.status & (Status.COASTING | Status.RESTING)]
    coast_s = (resting[0].board_ms - coasting[0].board_ms) * 1e-3
    return CutFigures(start, end, coasting[0].t - start, coast_s, amplitude,
                      after[0] - end if after else math.inf,
                      again[0] - end if again else math.inf)
