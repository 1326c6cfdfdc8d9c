# SPDX-License-Identifier: Apache-2.0
"""markers_every: body_wave_markers go out with every n-th body_wave."""

import pytest
from wirefish_kinematics.kinematics_node_parameters import markers_every, TABLE

SPECS = TABLE.by_name


@pytest.mark.parametrize(('publish_hz', 'markers_hz', 'every'), [
    (50.0, 10.0, 5), (50.0, 50.0, 1), (50.0, 20.0, 2), (200.0, 10.0, 20),
    (50.0, 500.0, 1),   # markers faster than the body wave: with every body wave, no more
    (50.0, 0.1, 500)])
def test_markers_every_is_the_rounded_rate_ratio_and_at_least_one(
        publish_hz, markers_hz, every):
    assert markers_every(publish_hz, markers_hz) == every


def test_markers_default_to_ten_hertz_of_a_fifty_hertz_body_wave():
    assert markers_every(SPECS['publish_rate_hz'].default,
                         SPECS['markers_rate_hz'].default) == 5
