# SPDX-License-Identifier: Apache-2.0
"""The decision of GoalSender: what the answers and the server's active goals say."""

import pytest
from wirefish_operator.goal_sender import goal_outcome, GoalOutcome

A, B = b'a' * 16, b'b' * 16
ACCEPTED, REJECTED, WAITING = GoalOutcome.ACCEPTED, GoalOutcome.REJECTED, GoalOutcome.WAITING


@pytest.mark.parametrize('answers, active, expected', [
    ({}, set(), (WAITING, None)),                       # nothing sent yet
    ({A: None}, set(), (WAITING, None)),                # sent, no answer, not running
    ({A: True}, set(), (ACCEPTED, A)),                  # answered accepted
    ({A: None}, {A}, (ACCEPTED, A)),                    # answer lost, the goal runs
    ({A: False}, set(), (REJECTED, None)),              # answered busy
    ({A: None, B: False}, {A}, (ACCEPTED, A)),          # the resend was busy with our first
    ({A: None, B: True}, set(), (ACCEPTED, B)),         # the resend was accepted
    ({A: None, B: False}, set(), (WAITING, None)),      # the first may still be answered
    ({A: False, B: False}, set(), (REJECTED, None)),    # every send answered busy
])
def test_the_outcome_of_the_goals_sent(answers, active, expected):
    assert goal_outcome(answers, active) == expected


def test_an_accepted_answer_wins_over_an_active_id_without_one():
    assert goal_outcome({A: None, B: True}, {A}) == (ACCEPTED, B)


def test_an_active_goal_of_someone_else_is_never_adopted():
    assert goal_outcome({A: None}, {B}) == (WAITING, None)
