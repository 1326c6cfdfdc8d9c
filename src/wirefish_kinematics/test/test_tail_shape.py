# SPDX-License-Identifier: Apache-2.0
"""The tail's shape at one pair of servo angles: eqs 2-4 then 7-15 on evenly spaced stations."""

import numpy as np
import pytest
from wirefish_kinematics.body_wave import body_positions, swing_angles
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.tail_shape import tail_shape
from wirefish_kinematics.wire_coupling import bend_angles

G = FishGeometry()


@pytest.mark.parametrize('servo', [(0.0, 0.0), (0.3, -0.2), (-0.38, 0.47)])
def test_the_shape_is_the_body_wave_of_the_bend_angles(servo):
    shape = tail_shape(servo, G, 7)
    beta1, beta2 = bend_angles(*servo, G)
    x, y = body_positions(shape.stations, beta1, beta2, G)
    np.testing.assert_array_equal(shape.x, x)
    np.testing.assert_array_equal(shape.y, y)
    assert (shape.beta1, shape.beta2) == (float(beta1), float(beta2))
    assert (shape.theta1, shape.theta2) == tuple(float(a) for a in swing_angles(beta1, beta2, G))


def test_the_stations_run_from_plate_one_to_the_tip():
    shape = tail_shape((0.1, 0.1), G, 5)
    np.testing.assert_allclose(shape.stations, np.linspace(0.0, G.tail_length, 5))


def test_the_link_ends_are_the_tail_at_l1_and_l1_plus_l2():
    shape = tail_shape((0.3, -0.2), G, 50)
    x, y = body_positions(np.array(G.link_end_stations), *bend_angles(0.3, -0.2, G), G)
    np.testing.assert_array_equal(shape.ends_x, x)
    np.testing.assert_array_equal(shape.ends_y, y)
