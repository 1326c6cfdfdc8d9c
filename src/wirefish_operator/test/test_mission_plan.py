# SPDX-License-Identifier: Apache-2.0
"""Mission files: parsing, refusals, the leg timeline, the shipped square."""

import math
from pathlib import Path

import pytest
from wirefish_operator.mission_plan import load_mission, mission_from

SQUARE = Path(__file__).resolve().parents[1] / 'missions' / 'square.yaml'


def test_the_shipped_square_is_four_straight_sides_and_four_quarter_turns():
    mission = load_mission(SQUARE)
    assert len(mission.legs) == 8
    turned = sum(leg.yaw_rate * leg.duration_s for leg in mission.legs)
    assert turned == pytest.approx(2 * math.pi, rel=1e-3)
    assert all(leg.speed > 0.0 for leg in mission.legs)


def test_command_at_follows_the_legs():
    mission = mission_from({'legs': [{'duration_s': 2.0, 'speed': 0.1},
                                     {'duration_s': 1.0, 'speed': 0.2, 'yaw_rate': 0.3}]})
    assert mission.command_at(-0.5) == (0.0, 0.0)  # resting before the first leg
    assert mission.command_at(1.9) == (0.1, 0.0)
    assert mission.command_at(2.5) == (0.2, 0.3)
    assert mission.command_at(3.0) is None  # over: cmd_vel stops
    assert mission.leg_starts() == [0.0, 2.0]


@pytest.mark.parametrize('data, words', [
    ({'legs': []}, 'non-empty'),
    ({'legs': [{'duration_s': 1.0}]}, 'leg 1: needs duration_s and speed'),
    ({'legs': [{'duration_s': 1.0, 'speed': -0.1}]}, 'backwards'),
    ({'legs': [{'duration_s': 0.0, 'speed': 0.1}]}, 'duration_s must be > 0'),
    ({'legs': [{'duration_s': 1.0, 'speed': float('nan')}]}, 'finite'),
    ({'legs': [{'duration_s': 1.0, 'speed': 0.1, 'turn': 1}]}, 'leg 1'),
    ({'legs': [{'duration_s': 1.0, 'speed': 0.1}, {'repeat': 0}]}, 'repeat'),
    ({'legs': [{'duration_s': 1.0, 'speed': 0.1}], 'coast_s': -1}, 'coast_s'),
])
def test_bad_missions_are_refused_with_the_reason(data, words):
    with pytest.raises(ValueError, match=words):
        mission_from(data)


def test_a_file_that_is_not_yaml_names_the_file(tmp_path):
    path = tmp_path / 'broken.yaml'
    path.write_text('legs: [\n')
    with pytest.raises(ValueError, match='broken.yaml'):
        load_mission(path)
