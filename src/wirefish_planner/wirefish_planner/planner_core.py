# SPDX-License-Identifier: Apache-2.0
"""
The planner's rules (pure; no rclpy): cmd_vel in, gait and turning offset out.

Modes (``PlannerMode``, PlannerState.mode)
    ``rest``      no cmd_vel yet, the last one older than ``cmd_vel_timeout_s`` (judged by an
                  on-time step: see ``LATE_STEP_FRACTION``), or speed 0:
                  amplitudes and offsets go to 0 (the CPG converges there smoothly), the
                  heading hold releases and the integrator empties.
    ``turn``      angular.z != 0: the yaw-rate PI tracks angular.z (REP-103: + turns left).
    ``hold``      angular.z = 0 with ``heading_hold``: the heading latched when the turn command
                  ended (or when swimming started) is held on the IMU yaw.
    ``straight``  angular.z = 0 without heading hold: the yaw-rate PI tracks 0.
    ``open_loop`` ``yaw_control`` off, or no IMU sample for ``imu_timeout_s``: the feed-forward
                  offset of angular.z alone.
    ``manual``    set by planner_node, not by these rules: the CPG is under a manual override.
    ``still``     set by planner_node: no command since start-up (``rest_at_start``): the CPG
                  has not been started and the planner holds its targets at rest, so the
                  servos stay at neutral until the first cmd_vel that asks to move, a manual
                  override (a retune applied) or the CPG's ``start``.
    ``own_gait``  set by planner_node: no cmd_vel since start-up with ``rest_at_start`` false:
                  the CPG swims its start-up parameters (`wirefish up --start-swimming`).
Speed: ``GaitPlanner.choose`` (eq 18 inverted, ``gait_choice``); turning: ``yaw_control``.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import math

from wirefish_planner.gait_choice import GaitChoice, GaitPlanner
from wirefish_planner.yaw_control import (feedforward_offset, heading_rate_reference,
                                          PeriodMean, wrap_angle, YawGains, YawRatePi)

REST_WINDOW_S = 0.5  # filter window while no gait beats (s)
SPEED_RESOLUTION_M_S = 0.001  # targets closer than this share a gait (no re-plan per message)
# A step this fraction of a timeout or more after the previous one comes from a planner that
# was itself asleep (a loaded machine): what arrived meanwhile still waits in its queues, so
# that step keeps the last judgement of the input and the next, on-time step judges it.
LATE_STEP_FRACTION = 0.5


class PlannerMode(enum.StrEnum):
    """What the planner does (the module docstring); the values of PlannerState.mode."""

    REST = 'rest'
    TURN = 'turn'
    HOLD = 'hold'
    STRAIGHT = 'straight'
    OPEN_LOOP = 'open_loop'
    MANUAL = 'manual'
    STILL = 'still'
    OWN_GAIT = 'own_gait'


@dataclass(frozen=True)
class PlannerSettings:
    """Timeouts (s) and which loops are closed."""

    cmd_vel_timeout_s: float = 0.5
    imu_timeout_s: float = 0.5
    heading_hold: bool = True
    yaw_control: bool = True

    def __post_init__(self) -> None:
        """Check the timeouts are finite and > 0."""
        for name in ('cmd_vel_timeout_s', 'imu_timeout_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f'{name} must be finite and > 0, got {value}')


@dataclass(frozen=True)
class PlannerOutput:
    """What the planner wants now, and why (the content of PlannerState)."""

    mode: PlannerMode
    gait: GaitChoice
    offset: float
    yaw_rate_target: float
    yaw_rate_measured: float
    heading_target: float  # nan without a hold
    heading_measured: float  # nan before the first IMU sample
    note: str  # '' or why a command could not be followed as given


def command_problem(speed: float, yaw_rate: float) -> str | None:
    """Return why a cmd_vel (linear.x m/s, angular.z rad/s) is refused, or None."""
    if not (math.isfinite(speed) and math.isfinite(yaw_rate)):
        return f'cmd_vel must be finite, got linear.x {speed}, angular.z {yaw_rate}'
    if speed < 0.0:
        return f'linear.x {speed:g} m/s refused: the fish cannot swim backwards'
    return None


def ignored_fields(linear: tuple[float, float, float],
                   angular: tuple[float, float, float]) -> list[str]:
    """Return the cmd_vel fields other than linear.x and angular.z that are not 0."""
    names = ('linear.y', 'linear.z', 'angular.x', 'angular.y')
    values = (linear[1], linear[2], angular[0], angular[1])
    return [name for name, value in zip(names, values) if value != 0.0]


class Planner:
    """Holds the latest command and IMU state; ``step`` returns what the CPG should do."""

    def __init__(self, gaits: GaitPlanner, gains: YawGains, settings: PlannerSettings) -> None:
        """Start at rest with no command and no IMU sample."""
        self.gaits = gaits
        self.settings = settings
        self.pi = YawRatePi(gains)
        self._speed = 0.0
        self._yaw_rate_cmd = 0.0
        self._command_s: float | None = None
        self._choice = GaitChoice(0.0, None)
        self._imu_s: float | None = None  # stamp of the last IMU sample
        self._imu_wall_s: float | None = None  # receipt time of the last IMU sample
        self._step_s: float | None = None
        self._command_lapsed = True  # judged by step: no cmd_vel, or none for the timeout
        self._imu_lapsed = True  # judged by step: no IMU sample, or none for the timeout
        self._unwrapped_yaw = math.nan
        self._rate_mean = PeriodMean(REST_WINDOW_S)
        self._yaw_mean = PeriodMean(REST_WINDOW_S)
        self._measured_rate = math.nan
        self._heading = math.nan
        self._heading_target = math.nan
        self._reference = 0.0
        self._was_turning = True  # swimming straight from rest latches the heading too

    def reconfigure(self, other: Planner) -> None:
        """Take ``other``'s gaits, gains and settings (new parameters); keep the run's state."""
        self.gaits, self.settings = other.gaits, other.settings
        self.pi.gains = other.pi.gains
        if not self.settings.heading_hold:
            self._heading_target = math.nan
        if math.isnan(self._heading_target):
            self._was_turning = True  # the next straight command latches the heading again
        if self._choice.point is not None:
            self._choose(self._choice.target_speed)

    # --- inputs -------------------------------------------------------------------------------
    def command(self, now_s: float, speed: float, yaw_rate: float) -> str | None:
        """Take a cmd_vel received at ``now_s``; return why it is refused (nothing changes)."""
        problem = command_problem(speed, yaw_rate)
        if problem is not None:
            return problem
        if self._command_lapsed:
            self._was_turning = True  # a new run latches its heading when it goes straight
        self._command_s = now_s
        self._command_lapsed = False
        self._speed = speed
        self._yaw_rate_cmd = yaw_rate
        if abs(speed - self._choice.target_speed) >= SPEED_RESOLUTION_M_S or \
                (speed == 0.0) != (self._choice.point is None):
            self._choose(speed)
        if yaw_rate != 0.0:
            self._was_turning = True
            self._heading_target = math.nan
        elif self._was_turning and self.settings.heading_hold:
            self._was_turning = False
            self._heading_target = self._heading_now()
        return None

    def imu(self, now_s: float, stamp_s: float, yaw: float, yaw_rate: float) -> None:
        """Take an IMU sample (stamp from its header) and run the yaw loop on its dt."""
        if not (math.isfinite(yaw) and math.isfinite(yaw_rate) and math.isfinite(stamp_s)):
            return
        previous = self._imu_s
        if previous is not None and stamp_s <= previous:
            return  # out of order or repeated: no dt
        self._unwrapped_yaw = yaw if math.isnan(self._unwrapped_yaw) else \
            self._unwrapped_yaw + wrap_angle(yaw - self._unwrapped_yaw)
        self._imu_s, self._imu_wall_s = stamp_s, now_s
        self._imu_lapsed = False
        self._measured_rate = self._rate_mean.add(stamp_s, yaw_rate)
        self._heading = self._yaw_mean.add(stamp_s, self._unwrapped_yaw)
        if math.isnan(self._heading_target) and not self._was_turning and \
                self.settings.heading_hold and self._swimming():
            self._heading_target = self._heading_now()  # the first sample of a straight run
        if previous is None or not self._swimming() or not self.settings.yaw_control:
            return
        self._reference = self._yaw_rate_reference()
        self.pi.update(self._reference, self._measured_rate, stamp_s - previous,
                       self._choice.predicted_speed)

    # --- outputs ------------------------------------------------------------------------------
    def step(self, now_s: float) -> PlannerOutput:
        """Return the gait, offset and state for now (timeouts are judged here)."""
        self._judge_timeouts(now_s)
        if not self._swimming():
            self.pi.reset()
            self._heading_target = math.nan
            self._was_turning = True
            note = ''
            if self._command_s is not None and not self._command_lapsed and \
                    self._yaw_rate_cmd != 0.0:
                note = 'turning needs forward speed (r = k U b): resting'
            return PlannerOutput(PlannerMode.REST, GaitChoice(0.0, None), 0.0, 0.0,
                                 self._measured_rate, math.nan, self._wrapped_heading(), note)
        speed = self._choice.predicted_speed
        if self.settings.yaw_control and not self._imu_lapsed:
            mode = PlannerMode.TURN if self._yaw_rate_cmd != 0.0 else (
                PlannerMode.HOLD if not math.isnan(self._heading_target)
                else PlannerMode.STRAIGHT)
            offset = self.pi.offset
            reference = self._reference
        else:
            mode = PlannerMode.OPEN_LOOP
            self.pi.reset()
            reference = self._yaw_rate_cmd
            limit = self.pi.gains.max_offset_rad
            offset = min(limit, max(-limit, feedforward_offset(
                reference, speed, self.pi.gains.turn_gain)))
        target = self._heading_target
        return PlannerOutput(mode, self._choice, offset, reference, self._measured_rate,
                             math.nan if math.isnan(target) else wrap_angle(target),
                             self._wrapped_heading(), '')

    # --- helpers ------------------------------------------------------------------------------
    def _choose(self, speed: float) -> None:
        """Choose the gait for ``speed``; the filters then average over its tail-beat period."""
        self._choice = self.gaits.choose(speed)
        window = (REST_WINDOW_S if self._choice.point is None
                  else 1.0 / self._choice.point.frequency_hz)
        self._rate_mean.window_s = self._yaw_mean.window_s = window

    def _judge_timeouts(self, now_s: float) -> None:
        """Judge whether cmd_vel and the IMU lapsed, unless this step comes late."""
        gap = 0.0 if self._step_s is None else now_s - self._step_s
        self._step_s = now_s
        s = self.settings
        if gap < LATE_STEP_FRACTION * s.cmd_vel_timeout_s:
            self._command_lapsed = self._command_s is None or \
                now_s - self._command_s > s.cmd_vel_timeout_s
        if gap < LATE_STEP_FRACTION * s.imu_timeout_s:
            self._imu_lapsed = self._imu_wall_s is None or \
                now_s - self._imu_wall_s > s.imu_timeout_s

    def _swimming(self) -> bool:
        return not self._command_lapsed and self._choice.point is not None

    def _heading_now(self) -> float:
        """Return the heading now: the period mean lags a turning fish by half its window."""
        if math.isnan(self._heading):
            return math.nan
        rate = 0.0 if math.isnan(self._measured_rate) else self._measured_rate
        return self._heading + 0.5 * self._yaw_mean.window_s * rate

    def _wrapped_heading(self) -> float:
        return math.nan if math.isnan(self._heading) else wrap_angle(self._heading)

    def _yaw_rate_reference(self) -> float:
        if self._yaw_rate_cmd != 0.0 or math.isnan(self._heading_target):
            return self._yaw_rate_cmd
        g = self.pi.gains
        return heading_rate_reference(self._heading_target, self._heading, g.heading_gain,
                                      g.max_hold_rate)
