# SPDX-License-Identifier: Apache-2.0
"""frame_prefix: frame ids that carry the fish's name."""

import pytest
from wirefish_common.frames import frame_prefix_problem, prefixed


@pytest.mark.parametrize('prefix, frame, expected', [
    ('', 'base_link', 'base_link'),
    ('fish_1', 'base_link', 'fish_1/base_link'),
    ('fish_1/', 'imu_link', 'fish_1/imu_link'),
    ('tank/fish_2', 'tail_base', 'tank/fish_2/tail_base'),
])
def test_a_prefix_goes_before_the_frame_with_one_slash(prefix, frame, expected):
    assert prefixed(prefix, frame) == expected


@pytest.mark.parametrize('prefix', ['', 'fish_1', 'tank/fish_2', 'fish_1/'])
def test_names_of_letters_digits_and_underscores_are_valid_prefixes(prefix):
    assert frame_prefix_problem(prefix) is None


@pytest.mark.parametrize('prefix', ['1fish', 'fish 1', '/fish_1', 'fish-1', 'a//b', 3])
def test_a_prefix_that_is_not_a_frame_name_is_refused_with_the_reason(prefix):
    assert 'frame_prefix' in frame_prefix_problem(prefix)
