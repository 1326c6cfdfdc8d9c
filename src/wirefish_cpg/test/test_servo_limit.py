# SPDX-License-Identifier: Apache-2.0
"""The servo limit on the CPG's output: clipped angles hold still at the limit."""

import numpy as np
import pytest
from wirefish_cpg.servo_limit import clamp_to_limit


def test_angles_within_the_limit_pass_unchanged():
    angles, rates, clipped = clamp_to_limit([0.3, -0.5], [1.0, -2.0], 0.5)
    assert (angles, rates, clipped) == ((0.3, -0.5), (1.0, -2.0), False)


@pytest.mark.parametrize('angles, expected_angles, expected_rates', [
    ([0.7, 0.1], [0.5, 0.1], [0.0, -2.0]),
    ([0.1, -0.9], [0.1, -0.5], [1.0, 0.0]),
    ([-0.6, 0.6], [-0.5, 0.5], [0.0, 0.0]),
])
def test_a_clipped_servo_sits_at_the_limit_with_rate_zero(angles, expected_angles,
                                                          expected_rates):
    out_angles, out_rates, clipped = clamp_to_limit(angles, [1.0, -2.0], 0.5)
    np.testing.assert_array_equal(out_angles, expected_angles)
    np.testing.assert_array_equal(out_rates, expected_rates)
    assert clipped
