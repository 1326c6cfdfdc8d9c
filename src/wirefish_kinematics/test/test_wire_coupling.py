# SPDX-License-Identifier: Apache-2.0
"""Wire coupling, eqs 2-4 and 21-22."""

import numpy as np
import pytest
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.wire_coupling import bend_angles, bend_rates, servo_angles_for

G = FishGeometry()


@pytest.mark.parametrize('servo_1, servo_2', [(0.0, 0.0), (0.38, 0.0), (0.0, 0.47),
                                              (0.38, -0.47), (-1.2, 0.9)])
def test_bend_angles_follow_eqs_3_and_4(servo_1, servo_2):
    beta1, beta2 = bend_angles(servo_1, servo_2, G)
    assert beta1 == pytest.approx(G.rd1 * servo_1 / G.r1, abs=1e-15)
    assert beta2 == pytest.approx(G.rd2 * servo_2 / G.r2 - beta1, abs=1e-15)
    # eq 2: wire pair lengths
    assert G.r1 * beta1 == pytest.approx(G.rd1 * servo_1, abs=1e-15)
    assert G.r2 * (beta1 + beta2) == pytest.approx(G.rd2 * servo_2, abs=1e-15)


def test_bend_rates_are_eqs_21_22_the_derivative_of_eqs_3_4():
    rates = bend_rates(np.array([1.5, -2.0]), np.array([0.3, 4.0]), G)
    h = 1e-6
    plus = np.array(bend_angles(np.array([1.5, -2.0]) * h, np.array([0.3, 4.0]) * h, G)) / h
    np.testing.assert_allclose(rates, plus, rtol=1e-9)


def test_servo_angles_for_inverts_bend_angles():
    servo = np.array([[0.38, -0.47], [-0.1, 0.2]])
    back = servo_angles_for(*bend_angles(servo[:, 0], servo[:, 1], G), G)
    np.testing.assert_allclose(np.stack(back, axis=-1), servo, rtol=1e-14)


def test_angles_broadcast():
    beta1, beta2 = bend_angles(np.zeros((3, 1)), np.zeros((1, 4)), G)
    assert beta1.shape == (3, 1) and beta2.shape == (3, 4)
