# SPDX-License-Identifier: Apache-2.0
"""fish_sim's fault windows (--reopen-every, --stall-every): due on time, late, never skipped."""

from wirefish_sim.fish_sim import Schedule


def _events(schedule: Schedule, times: list[float]) -> list[int | None]:
    return [schedule.index(t) for t in times]


def test_each_event_is_active_from_its_due_time_for_its_duration():
    schedule = Schedule(1.5, 0.3)
    assert _events(schedule, [0.0, 1.49, 1.5, 1.79, 1.8, 2.9, 3.0]) == [
        None, None, 1, 1, None, None, 2]


def test_a_loop_starved_past_a_whole_window_still_has_the_event_late():
    schedule = Schedule(1.5, 0.3, count=5)
    # The loop slept from 1.4 s to 2.0 s: past event 1's window (1.5-1.8 s).
    assert _events(schedule, [1.4, 2.0, 2.29, 2.3, 3.0]) == [None, 1, 1, None, 2]


def test_events_starved_together_come_one_after_the_other_with_none_between():
    # None between: the device a reopen closed opens again before the next one closes it.
    schedule = Schedule(1.0, 0.25)
    assert _events(schedule, [3.5, 3.6, 3.8, 3.85, 3.9, 4.2, 4.25]) == [
        1, 1, None, 2, 2, None, 3]


def test_no_event_beyond_the_count_and_none_when_never():
    two = Schedule(1.0, 0.1, count=2)
    assert _events(two, [1.0, 1.5, 2.0, 2.5, 3.0, 4.0]) == [1, None, 2, None, None, None]
    assert _events(Schedule(0.0, 0.3), [0.0, 10.0]) == [None, None]
