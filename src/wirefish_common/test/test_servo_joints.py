# SPDX-License-Identifier: Apache-2.0
"""The one JointState <-> servo-pair conversion: names, sizes, finite values, round trip."""

import math

from builtin_interfaces.msg import Time
import pytest
from sensor_msgs.msg import JointState
from wirefish_common.servo_joints import (JointProblem, servo_angles, servo_joint_state,
                                          SERVO_JOINTS, servo_sample)


def joint_state(names, positions, velocities=()) -> JointState:
    return JointState(name=list(names), position=list(positions), velocity=list(velocities))


def test_the_joint_names_are_servo_1_and_servo_2():
    assert SERVO_JOINTS == ('servo_1', 'servo_2')


@pytest.mark.parametrize('names, positions, expected', [
    (('servo_1', 'servo_2'), (0.1, -0.2), (0.1, -0.2)),
    (('servo_2', 'servo_1'), (0.1, -0.2), (-0.2, 0.1)),
    (('fin', 'servo_2', 'servo_1'), (9.0, 0.3, 0.4), (0.4, 0.3)),
])
def test_angles_are_found_by_name_in_any_order_among_other_joints(names, positions, expected):
    assert servo_angles(joint_state(names, positions)) == pytest.approx(expected)


@pytest.mark.parametrize('names, positions, kind', [
    ((), (0.1, 0.2), 'names'),  # unnamed positions: refused (see the module docstring)
    (('servo_1',), (0.1,), 'names'),
    (('servo_1', 'servo_2', 'third_joint_without_position'), (0.1, 0.2), 'size'),
    (('servo_1', 'servo_2'), (0.1,), 'size'),
    (('servo_1', 'servo_2'), (math.nan, 0.2), 'angles'),
    (('servo_1', 'servo_2'), (0.1, math.inf), 'angles'),
])
def test_unusable_joint_states_give_a_problem_of_their_kind(names, positions, kind):
    problem = servo_angles(joint_state(names, positions))
    assert isinstance(problem, JointProblem) and problem.kind == kind


def test_a_missing_joint_is_named_in_the_message():
    problem = servo_angles(joint_state(('servo_1',), (0.1,)))
    assert f'JointState needs joints {SERVO_JOINTS}' in problem.message


def test_a_sample_takes_the_velocities_in_the_order_of_the_names():
    sample = servo_sample(joint_state(('servo_2', 'servo_1'), (0.1, 0.2), (1.0, 2.0)))
    assert sample == ((0.2, 0.1), (2.0, 1.0))


@pytest.mark.parametrize('velocities', [(), (1.0,)])
def test_a_sample_without_one_velocity_per_name_has_unknown_rates(velocities):
    _, rates = servo_sample(joint_state(SERVO_JOINTS, (0.1, 0.2), velocities))
    assert all(math.isnan(r) for r in rates)


def test_a_sample_with_non_finite_velocities_is_unusable():
    problem = servo_sample(joint_state(SERVO_JOINTS, (0.1, 0.2), (math.nan, 0.0)))
    assert isinstance(problem, JointProblem) and problem.kind == 'rates'


def test_a_sample_of_a_bad_joint_state_has_the_angle_problem():
    problem = servo_sample(joint_state((), (0.1, 0.2), (0.0, 0.0)))
    assert isinstance(problem, JointProblem) and problem.kind == 'names'


def test_written_joint_states_read_back_to_the_same_sample():
    msg = servo_joint_state((0.25, -0.5), (1.5, -2.0), Time(sec=3, nanosec=7))
    assert servo_sample(msg) == ((0.25, -0.5), (1.5, -2.0))
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (3, 7)


def test_a_joint_state_written_without_rates_has_no_velocity():
    msg = servo_joint_state((0.25, -0.5))
    assert list(msg.name) == list(SERVO_JOINTS) and len(msg.velocity) == 0


@pytest.mark.parametrize('angles, rates', [((0.1,), None), ((0.1, 0.2, 0.3), None),
                                           ((0.1, 0.2), (1.0,))])
def test_writing_the_wrong_number_of_values_is_refused(angles, rates):
    with pytest.raises(ValueError, match='servo_1'):
        servo_joint_state(angles, rates)
