# SPDX-License-Identifier: Apache-2.0
"""
The planner's acceptance on the virtual fish, across processes, measured on sim/ground_truth.

One graph (fish_sim with a constant yaw disturbance, bridge, CPG, planner) on the virtual
fish's clock (lockstep, --speed max: every time below is simulated time, so a loaded machine
slows the drive down and changes nothing in it) and one drive in phases, because each phase
needs many seconds of swimming: rest before any cmd_vel; speed
setpoints 0.10 / 0.20 / 0.30 m/s; 0.6 m/s clamped (planner_state, /diagnostics); yaw rate
+-0.2 rad/s at 0.2 m/s; heading hold against the current, then the same straight run with the
hold off (rate loop only) and with the yaw loop off (open loop), printed; cmd_vel stops. The
servo commands of the whole drive are checked for steps at every switch. The
drive runs once per module (the ``drive`` fixture); each test judges one of its claims.
The square mission has a file (and so a graph and an xdist worker) of its own:
test_planner_mission.py.
"""

from collections import Counter
from dataclasses import dataclass
import math
import time

import numpy as np
import pytest

SETTLE_S = 7.0  # surge ~1.5 s time constant (drag ~ U^2 about the force scale) x 4 and more
SPEED_WINDOW_S = 5.0
TURN_SETTLE_S = 4.0
TURN_WINDOW_S = 5.0
HOLD_SETTLE_S = 5.0
HOLD_WINDOW_S = 15.0
OFF_WINDOW_S = 10.0  # open loop drifts ~0.5 rad in it against the 0.05 rad/s current
STOP_WITHIN_S = 5.0
MAX_CPG_ACCELERATION = 300.0  # rad/s^2 (see the servo check)
# As fast as the graph answers: the planner holds the clock at each control tick until its
# imu/data has caught up with it, and the phases are counted in simulated seconds. The driver
# holds the clock at each of its cmd_vel periods too (conftest.Driver).
GRAPH_SPEED = 'max'


def _window(rows: list, start: float, end: float) -> np.ndarray:
    data = np.array([r for r in rows if start <= r[0] < end])
    assert len(data) > 10, f'too few samples in [{start:.1f}, {end:.1f})'
    return data


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def _rate(servo: list, start: float, end: float) -> float:
    return sum(1 for r in servo if start <= r[0] < end) / (end - start)


def _hold(driver, command: tuple[float, float], seconds: float) -> tuple[float, float]:
    driver.command = command
    start = driver.now()
    driver.sleep(seconds)  # of simulated time: the graph runs on fish_sim's clock
    return start, driver.now()


@dataclass(frozen=True)
class Drive:
    """What the drive measured, phase by phase (see the module's docstring)."""

    rest_amplitude: float
    rest_mode: str
    results: dict
    clamped: object
    warned: list
    turns: dict
    hold_rms: float
    drifts: dict
    stop_time: float
    worst: float


@pytest.fixture(scope='module')
def drive(driver) -> Drive:
    """Drive the virtual fish through every phase once; return what each phase measured."""
    rec = driver.recording
    deadline = time.monotonic() + 30.0
    # Discovery on a loaded machine: each stream its own writer in its own process (a clean-clone
    # run heard ground truth and planner_state, but not yet one servo_cmd).
    while len(rec.truth) < 50 or len(rec.state) < 10 or len(rec.servo) < 50:
        assert time.monotonic() < deadline, \
            'no ground truth / planner_state / servo_cmd from the graph'
        time.sleep(0.1)
    # No cmd_vel ever received: the fish starts still (cpg_node's autostart false in the
    # graph's parameters) and the planner holds it there, saying so.
    rest_deadline = time.monotonic() + 20.0
    while True:
        driver.sleep(1.0)
        t0 = driver.now()
        resting = _window(rec.servo, t0 - 1.0, t0)  # servo stamps: the CPG node's clock
        rest_amplitude = np.abs(resting[:, 1:3]).max()
        if rest_amplitude < 0.02 or time.monotonic() > rest_deadline:
            break
    print(f'rest before any cmd_vel: max |servo_cmd| over 1 s {rest_amplitude:.4f} rad')
    rest_mode = rec.state[-1][1].mode

    results = {}
    for setpoint in (0.10, 0.20, 0.30):
        start, end = _hold(driver, (setpoint, 0.0), SETTLE_S + SPEED_WINDOW_S)
        speed = _window(rec.truth, start + SETTLE_S, end)[:, 4].mean()
        results[setpoint] = speed
        print(f'speed setpoint {setpoint:.2f} m/s: ground truth mean {speed:.4f} m/s '
              f'({100 * (speed / setpoint - 1):+.1f} %), predicted '
              f'{rec.state[-1][1].predicted_speed:.4f} at {rec.state[-1][1].tail_beat_hz:.2f} Hz '
              f'(the CPG runs v = {rec.state[-1][1].cpg_frequency_hz:.3f} Hz); servo_cmd '
              f'{_rate(rec.servo, start, end):.0f} Hz heard')

    # Above the fastest feasible gait: clamped, the reason in planner_state and /diagnostics.
    start, end = _hold(driver, (0.6, 0.0), 2.5)
    clamped = rec.state[-1][1]
    warned = [s for t, s in rec.diagnostics if t >= start + 1.0]
    print(f'0.60 m/s asked: predicted {clamped.predicted_speed:.3f} m/s; '
          f'{clamped.clamp_reason}; diagnostics: {warned[-1].message if warned else None}')

    turns = {}
    for rate in (0.2, -0.2):
        start, end = _hold(driver, (0.2, rate), TURN_SETTLE_S + TURN_WINDOW_S)
        turns[rate] = _window(rec.truth, start + TURN_SETTLE_S, end)[:, 5].mean()
        print(f'yaw-rate setpoint {rate:+.2f} rad/s at 0.2 m/s: ground truth mean '
              f'{turns[rate]:+.4f} rad/s ({100 * (turns[rate] / rate - 1):+.1f} %)')

    # The turn ends: the heading it had then is held against the current.
    start, end = _hold(driver, (0.2, 0.0), HOLD_SETTLE_S + HOLD_WINDOW_S)
    hold_target = rec.state[-1][1].heading_target
    held = _window(rec.truth, start + HOLD_SETTLE_S, end)
    hold_rms = math.degrees(math.sqrt(np.mean(_wrap(held[:, 3] - hold_target) ** 2)))
    hold_modes = Counter(m.mode for t, m in rec.state if start + HOLD_SETTLE_S <= t < end)
    print(f'heading hold with a {0.05:.2f} rad/s current: target {math.degrees(hold_target):.1f}'
          f' deg, RMS error over {HOLD_WINDOW_S:.0f} s {hold_rms:.2f} deg (planner modes '
          f'{dict(hold_modes)})')

    drifts = {}
    for name, values in (('heading hold off (yaw-rate loop only)', {'heading_hold': False}),
                         ('yaw loops off (open loop)', {'yaw_control': False})):
        driver.set_parameters('planner_node', **values)
        start, end = _hold(driver, (0.2, 0.0), OFF_WINDOW_S)
        off = _window(rec.truth, start, end)
        drifts[name] = math.degrees(_wrap(off[-1, 3] - off[0, 3]))
        modes = Counter(m.mode for t, m in rec.state if start <= t < end)
        print(f'{name}: heading drifts {drifts[name]:+.1f} deg in {end - start:.0f} s '
              f'(planner modes {dict(modes)})')
        driver.set_parameters('planner_node', heading_hold=True, yaw_control=True)

    driver.command = None  # cmd_vel stops
    stopped = driver.now()
    driver.sleep(STOP_WITHIN_S + 1.0)
    after = np.array([r for r in rec.truth if r[0] >= stopped])
    slow = after[after[:, 4] < 0.02]
    stop_time = slow[0, 0] - stopped if len(slow) else math.inf
    print(f'cmd_vel stopped: ground-truth speed < 0.02 m/s after {stop_time:.2f} s; '
          f'mode {rec.state[-1][1].mode}')

    servo = np.array(rec.servo)
    servo = servo[np.argsort(servo[:, 0])]
    dt = np.diff(servo[:, 0])
    steps = np.abs(np.diff(servo[:, 1:3], axis=0))
    # The CPG's smooth bound: between two samples the command moves no more than its larger
    # reported rate allows plus its largest acceleration (R (2 pi f)^2 <= 2 pi f_max x slew
    # limit ~ 230 rad/s^2 for the planner's gaits; 300 taken), never by a jump. Pairs further
    # apart than 20 ms (samples lost to a loaded machine) show no step and are not judged.
    close = dt <= 0.02
    bound = np.maximum(np.abs(servo[:-1, 3:5]), np.abs(servo[1:, 3:5])) * dt[:, None] \
        + 0.5 * MAX_CPG_ACCELERATION * dt[:, None] ** 2 + 1e-3
    worst = float((steps - bound)[close].max())
    print(f'servo_cmd: {len(servo)} samples, {int(close.sum())} pairs <= 20 ms apart judged; '
          f'largest change there {steps[close].max():.4f} rad, largest excess over the smooth '
          f'bound {worst:.5f} rad; longest gap {dt.max():.3f} s, {int((dt > 0.05).sum())} gaps '
          '> 50 ms')
    return Drive(rest_amplitude, rest_mode, results, clamped, warned, turns, hold_rms, drifts,
                 stop_time, worst)


@pytest.mark.ros
def test_the_fish_rests_before_any_cmd_vel(drive):
    assert drive.rest_amplitude < 0.02
    assert drive.rest_mode == 'still'


@pytest.mark.ros
@pytest.mark.parametrize('setpoint', (0.10, 0.20, 0.30))
def test_each_speed_setpoint_is_swum_within_ten_percent(drive, setpoint):
    speed = drive.results[setpoint]
    assert abs(speed - setpoint) <= 0.10 * setpoint, (setpoint, speed)


@pytest.mark.ros
def test_a_speed_above_the_fastest_gait_is_clamped_with_the_reason(drive):
    assert 'above the fastest feasible gait' in drive.clamped.clamp_reason
    assert drive.clamped.predicted_speed < 0.6


@pytest.mark.ros
def test_the_clamp_is_a_warning_on_diagnostics(drive):
    warned = drive.warned
    assert warned and warned[-1].level == b'\x01' and 'clamped' in warned[-1].message


@pytest.mark.ros
@pytest.mark.parametrize('rate', (0.2, -0.2))
def test_each_yaw_rate_setpoint_is_turned_within_twenty_percent(drive, rate):
    measured = drive.turns[rate]
    assert np.sign(measured) == np.sign(rate) and abs(measured - rate) <= 0.2 * abs(rate)


@pytest.mark.ros
def test_the_heading_is_held_against_the_current(drive):
    assert drive.hold_rms < 3.0


@pytest.mark.ros
def test_without_the_yaw_loops_the_current_turns_the_fish(drive):
    assert abs(drive.drifts['yaw loops off (open loop)']) > 3.0 * drive.hold_rms


@pytest.mark.ros
def test_the_fish_stops_when_cmd_vel_stops(drive):
    assert drive.stop_time <= STOP_WITHIN_S


@pytest.mark.ros
def test_the_servo_commands_never_step(drive):
    assert drive.worst <= 0.0
