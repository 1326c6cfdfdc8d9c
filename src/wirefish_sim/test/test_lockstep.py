# SPDX-License-Identifier: Apache-2.0
"""The virtual fish's clock: lockstep with the host's commands, a pace, never a dropped step."""

import math

import pytest
from wirefish_common.clock_hold import RELEASED_NS
from wirefish_common.input_checks import parse_speed, speed_text
from wirefish_sim.lockstep import clock_origin_ns, ENGAGE_STEPS, LockstepClock

STEP_NS = 10_000_000
PLANNER = '/fish/planner_node'  # the holding nodes, by their fully qualified names
KINEMATICS = '/fish/kinematics_node'


def _engaged_clock(speed: float = math.inf, fish: int = 1) -> LockstepClock:
    clock = LockstepClock(0, STEP_NS, speed, fish, wall_now_s=0.0, grace_s=2.0)
    for step in range(ENGAGE_STEPS):  # not engaged yet: paced at real time
        for index in range(fish):
            clock.on_command(index)
        assert clock.ready(0.01 * step)
        clock.advance(0.01 * step)
    assert all(clock.engaged)
    return clock


def test_a_streaming_host_holds_every_step_until_its_command_arrives():
    clock = _engaged_clock()
    before = clock.time_ns
    assert not clock.ready(0.5)  # no command yet: simulated time waits
    assert not clock.ready(1.0)
    clock.on_command(0)
    assert clock.ready(1.0)
    clock.advance(1.0)
    assert clock.time_ns == before + STEP_NS  # one whole step, whatever the wall time
    assert clock.counters.lockstep_steps == 1


def test_the_clock_waits_for_every_engaged_fish_of_a_fleet():
    clock = _engaged_clock(fish=3)
    clock.on_command(0)
    clock.on_command(2)
    assert clock.waiting_for() == [1]
    assert not clock.ready(1.0)
    clock.on_command(1)
    assert clock.ready(1.0)


def test_a_host_silent_for_the_grace_is_released_and_time_follows_the_wall_clock():
    clock = _engaged_clock()
    assert not clock.ready(10.0)  # the wait starts
    assert clock.wait_s(10.0) == pytest.approx(2.0)
    assert not clock.ready(11.9)
    assert clock.ready(12.0)  # waited out: the fish no longer holds the clock
    assert clock.counters.releases == 1 and not any(clock.engaged)
    clock.advance(12.0)
    # Released at --speed max, the pace is real time: the next step one step of wall later.
    assert not clock.ready(12.005)
    assert clock.ready(12.01)


def test_the_bridges_neutral_at_10_hz_is_no_stream_and_engages_nothing():
    clock = LockstepClock(0, STEP_NS, 1.0, 1, wall_now_s=0.0)
    wall = 0.0
    for step in range(100):
        if step % 10 == 0:
            clock.on_command(0)
        while not clock.ready(wall):
            wall += 0.001
        clock.advance(wall)
    assert not clock.engaged[0]


def test_speed_one_paces_steps_at_real_time_and_a_late_step_is_not_made_up_by_a_burst():
    clock = LockstepClock(0, STEP_NS, 1.0, 1, wall_now_s=0.0)
    assert clock.ready(0.0)
    clock.advance(0.0)
    assert not clock.ready(0.009) and clock.ready(0.01)
    clock.advance(0.5)  # the machine stalled: this step was taken 0.49 s late
    assert not clock.ready(0.509)  # re-anchored: the next step a whole step later, no burst
    assert clock.ready(0.51)
    assert clock.time_ns == 2 * STEP_NS  # slower, never a dropped step


def test_max_speed_steps_as_soon_as_the_command_is_there():
    clock = _engaged_clock(math.inf)
    for _ in range(50):  # no wall time passes: engaged at max, only the commands pace it
        clock.on_command(0)
        assert clock.ready(1.0)
        clock.advance(1.0)
    assert clock.counters.lockstep_steps == 50


def test_speed_text_and_parse():
    assert parse_speed('max') == math.inf and parse_speed('1') == 1.0
    assert parse_speed(' MAX ') == math.inf and parse_speed('2.5') == 2.5
    for bad in ('0', '-1', 'nan', 'inf', 'fast'):
        with pytest.raises(ValueError, match='--speed'):
            parse_speed(bad)
    assert speed_text(math.inf) == 'max' and speed_text(4.0) == '4'


def test_simulated_time_starts_on_a_whole_step_of_the_wall_clock():
    assert clock_origin_ns(1_234_567_891_234, STEP_NS) == 1_234_560_000_000
    with pytest.raises(ValueError):
        LockstepClock(0, 0, 1.0, 1, 0.0)


def test_a_holding_node_keeps_the_clock_at_its_next_tick_until_it_answers():
    clock = _engaged_clock()
    tick = clock.time_ns + 2 * STEP_NS
    clock.on_hold(0, PLANNER, tick)
    for wall in (1.0, 1.01):  # up to the tick: the commands alone decide
        clock.on_command(0)
        assert clock.ready(wall)
        clock.advance(wall)
    assert clock.time_ns == tick
    clock.on_command(0)
    assert clock.held_by() == [(0, PLANNER)] and not clock.ready(1.02)  # the tick's answer is owed
    clock.on_hold(0, PLANNER, tick + 5 * STEP_NS)
    assert clock.held_by() == [] and clock.ready(1.02)


def test_a_holding_node_that_says_it_is_done_holds_the_clock_no_more():
    # A mission at its end (clock_hold.ClockHold.release): no wait for the grace.
    clock = _engaged_clock()
    clock.on_hold(0, PLANNER, clock.time_ns)
    clock.on_command(0)
    assert clock.held_by() == [(0, PLANNER)]
    clock.on_hold(0, PLANNER, RELEASED_NS)
    assert clock.held_by() == [] and clock.ready(1.0)


def test_a_holding_node_silent_for_the_grace_is_released_until_it_answers_again():
    clock = _engaged_clock()
    clock.on_hold(0, PLANNER, clock.time_ns)
    clock.on_command(0)
    assert not clock.ready(10.0)
    assert clock.wait_s(10.0) == pytest.approx(2.0)
    assert clock.ready(12.0)
    assert clock.counters.hold_releases == 1 and clock.held_by() == []
    assert clock.counters.releases == 0  # the host streamed: it still holds the clock
    clock.advance(12.0)
    clock.on_hold(0, PLANNER, clock.time_ns)  # back: it holds again
    clock.on_command(0)
    assert clock.held_by() == [(0, PLANNER)] and not clock.ready(12.01)


def test_each_fish_of_a_fleet_is_held_by_its_own_node():
    clock = _engaged_clock(fish=2)
    clock.on_hold(1, PLANNER, clock.time_ns)
    clock.on_command(0)
    clock.on_command(1)
    assert clock.held_by() == [(1, PLANNER)] and not clock.ready(1.0)


def test_two_nodes_hold_one_fish_and_the_step_waits_for_the_later_answer():
    clock = _engaged_clock()
    clock.on_hold(0, PLANNER, clock.time_ns + 4 * STEP_NS)
    clock.on_hold(0, KINEMATICS, clock.time_ns)
    clock.on_command(0)
    assert clock.held_by() == [(0, KINEMATICS)] and not clock.ready(1.0)
    clock.on_hold(0, KINEMATICS, clock.time_ns + 2 * STEP_NS)
    assert clock.held_by() == [] and clock.ready(1.0)


def test_a_silent_holder_is_released_while_the_other_still_holds():
    clock = _engaged_clock()
    clock.on_hold(0, PLANNER, clock.time_ns)
    clock.on_hold(0, KINEMATICS, clock.time_ns)
    clock.on_command(0)
    assert not clock.ready(10.0)
    clock.on_hold(0, PLANNER, clock.time_ns + STEP_NS)  # answers; the kinematics never does
    assert clock.ready(12.0)
    assert clock.counters.hold_releases == 1
    clock.advance(12.0)
    clock.on_command(0)
    assert clock.held_by() == [(0, PLANNER)]  # the one that answered holds at its next tick


def test_a_restarted_holder_takes_its_predecessors_place():
    clock = _engaged_clock()
    clock.on_hold(0, KINEMATICS, clock.time_ns)  # then killed: its tick is owed
    clock.on_command(0)
    assert not clock.ready(1.0)
    clock.on_hold(0, KINEMATICS, clock.time_ns + STEP_NS)  # the restarted node, same name
    assert clock.ready(1.0) and clock.counters.hold_releases == 0
