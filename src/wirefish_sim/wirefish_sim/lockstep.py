# SPDX-License-Identifier: Apache-2.0
"""
When the virtual fish may take its next step of simulated time (pure: no ROS, no I/O).

On the simulated-time road fish_sim owns the graph's clock (``/clock``) and advances it in
steps of ``step_ns`` (10 ms: one period of the CPG's servo_cmd, which the bridge forwards as
one SERVO_CMD per step). A step is taken when two things hold:

- the pace: not before ``step / speed`` of wall time after the last step (``speed`` 1: real
  time when the machine keeps up; ``math.inf``, ``--speed max``: as fast as the graph
  answers). A step that comes late is never made up by a burst: the pace re-anchors, so a
  slow machine makes simulated time run slower, never jump;
- lockstep: every fish whose host streams SERVO_CMD ("engaged") has received the command of
  this step since the last one. Simulated time then waits for the slowest of the CPG, the
  bridge and the pty, as PX4's SITL waits for the autopilot's actuator output.

A fish is engaged once SERVO_CMD arrived in ``ENGAGE_STEPS`` consecutive steps (a stream at
the step rate; the bridge's neutral at 10 Hz of a failsafe is no stream), and released when it
waited ``grace_s`` of wall time for a command (its CPG was killed, stopped streaming, or the
board left stream mode: in gait mode the board integrates the CPG itself and no SERVO_CMD
streams). A released fish does not hold the clock: simulated time then follows the wall
clock at ``speed`` (``max``: at real time, so a graph without a host cannot run away with
simulated time), which is also what paces the clock before the host starts and in gait mode.
So the clock never waits for ever: at worst a step takes ``grace_s``, after which time runs
at the wall-clock pace. Nothing is ever dropped: every step is ``step_ns`` of simulated time.

A node whose timer must see every period of simulated time holds the clock too: the planner's
control loop (its cmd_vel tracking and yaw loops act through the CPG's targets) and the
kinematics' tick (it takes the servo samples from a queue a few ticks deep). After each tick
such a node says when its next one is due (``on_hold``, under its name: several nodes may hold
one fish's clock), and no step goes past that time until its next answer. Without it a graph at
``--speed max`` could outrun the node: its timer would skip periods, or its queue overflow, and
the experiment would change with the machine (at --speed max beside two other graphs the
kinematics lost 1 % of its servo samples, body_wave 49.5 Hz of 50). A node that stops answering
is released after ``grace_s`` as a silent host is, and holds again at its next answer; a
restarted node answers under its predecessor's name and takes its place.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

# Consecutive steps with a SERVO_CMD that make a fish's host a stream (see the module doc).
ENGAGE_STEPS = 2
# How long (wall s) an engaged fish may keep the clock waiting for its command: far above a
# round trip through the CPG and the bridge on a loaded machine (tens of ms beside two CPU
# hogs on one core). At 2 s a CPG starved while other nodes restarted (load ~10 on 2 cores)
# released the clock, and the streams it feeds paused 1-3 s of simulated time.
DEFAULT_GRACE_S = 5.0


@dataclass
class LockstepCounters:
    """What the clock did: steps, steps taken in lockstep, releases for a silent host."""

    steps: int = 0
    lockstep_steps: int = 0
    releases: int = 0
    hold_releases: int = 0


class LockstepClock:
    """The simulated clock of ``fish_count`` fish; times in ns (simulated) and s (wall)."""

    def __init__(self, origin_ns: int, step_ns: int, speed: float, fish_count: int,
                 wall_now_s: float, grace_s: float = DEFAULT_GRACE_S) -> None:
        """Start at ``origin_ns`` of simulated time, at wall time ``wall_now_s``."""
        if step_ns <= 0 or fish_count < 1 or not speed > 0.0 or not grace_s > 0.0:
            raise ValueError('a lockstep clock needs a step > 0, a fish, a speed > 0 and a '
                             'grace > 0')
        self.time_ns = origin_ns
        self.step_ns = step_ns
        self.speed = speed
        self.grace_s = grace_s
        self.engaged = [False] * fish_count
        self.counters = LockstepCounters()
        self._commanded = [False] * fish_count
        self._streak = [0] * fish_count
        self._next_wall_s = wall_now_s
        self._waiting_since_s: float | None = None
        # Per fish: the simulated time (ns) each of its holding nodes' next tick is due, by name.
        self._holds: list[dict[str, int]] = [{} for _ in range(fish_count)]

    @property
    def time_s(self) -> float:
        """Return the simulated time (s)."""
        return self.time_ns * 1e-9

    def pace(self) -> float:
        """Return the factor on real time the pace follows now (see the module doc)."""
        if any(self.engaged):
            return self.speed
        return 1.0 if math.isinf(self.speed) else self.speed

    def on_command(self, fish: int) -> None:
        """Note that fish ``fish`` received a SERVO_CMD during the current step."""
        self._commanded[fish] = True

    def on_hold(self, fish: int, holder: str, next_tick_ns: int) -> None:
        """Note that ``holder``, a node holding fish ``fish``'s clock, answered; its next tick."""
        self._holds[fish][holder] = next_tick_ns

    def waiting_for(self) -> list[int]:
        """Return the engaged fish whose command of this step has not arrived."""
        return [f for f, engaged in enumerate(self.engaged) if engaged and not self._commanded[f]]

    def held_by(self) -> list[tuple[int, str]]:
        """Return (fish, holder) of each holding node that owes a tick the step would pass."""
        next_ns = self.time_ns + self.step_ns
        return [(fish, holder) for fish, holds in enumerate(self._holds)
                for holder, due_ns in sorted(holds.items()) if next_ns > due_ns]

    def ready(self, wall_now_s: float) -> bool:
        """Return whether the next step may be taken now (releasing what is silent too long)."""
        if wall_now_s < self._next_wall_s:
            return False
        waiting, held = self.waiting_for(), self.held_by()
        if not waiting and not held:
            return True
        if self._waiting_since_s is None:
            self._waiting_since_s = wall_now_s
            return False
        if wall_now_s - self._waiting_since_s < self.grace_s:
            return False
        for fish in waiting:  # its host went silent: it no longer holds the clock
            self.engaged[fish] = False
            self._streak[fish] = 0
            self.counters.releases += 1
        for fish, holder in held:  # a holding node went silent: it holds again when it answers
            del self._holds[fish][holder]
            self.counters.hold_releases += 1
        return True

    def wait_s(self, wall_now_s: float) -> float:
        """Return how long (wall s) nothing can change ``ready`` unless an answer arrives."""
        until = self._next_wall_s - wall_now_s
        if (self.waiting_for() or self.held_by()) and self._waiting_since_s is not None:
            until = max(until, self._waiting_since_s + self.grace_s - wall_now_s)
        return max(0.0, until)

    def advance(self, wall_now_s: float) -> None:
        """Take the step: simulated time moves on by ``step_ns``; engagement is updated."""
        self.counters.steps += 1
        if any(self.engaged) and not self.waiting_for() and not self.held_by():
            self.counters.lockstep_steps += 1
        for fish, commanded in enumerate(self._commanded):
            self._streak[fish] = self._streak[fish] + 1 if commanded else 0
            if self._streak[fish] >= ENGAGE_STEPS:
                self.engaged[fish] = True
            self._commanded[fish] = False
        self._waiting_since_s = None
        self.time_ns += self.step_ns
        period_s = self.step_ns * 1e-9 / self.pace()
        following = self._next_wall_s + period_s
        # A step behind the pace re-anchors it: no burst to make up for a slow machine.
        self._next_wall_s = (following if following >= wall_now_s - period_s
                             else wall_now_s + period_s)


def clock_origin_ns(wall_now_ns: int, step_ns: int) -> int:
    """Return where simulated time starts: the wall clock's time, on a whole step."""
    # Near the system clock (a stamp reads as a date) and, at speed <= 1, later than a
    # previous run's simulated time: a restarted fish_sim moves the graph's clock forward.
    return wall_now_ns // step_ns * step_ns
