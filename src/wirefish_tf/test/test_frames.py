# SPDX-License-Identifier: Apache-2.0
"""The frames' pure core: mounts, the moving tail frames and dead reckoning."""

import math

import numpy as np
import pytest
from wirefish_kinematics.body_wave import body_positions
from wirefish_kinematics.geometry import FishGeometry
from wirefish_tf.frames import (dead_reckoned, Frame, PlanarPose, quaternion_yaw,
                                tail_base_in_base_link, tail_frames, yaw_quaternion)

GEOMETRY = FishGeometry()


def test_plate_i_sits_a_body_length_less_the_tail_behind_the_nose_facing_aft():
    pose = tail_base_in_base_link(GEOMETRY)
    assert pose.x == pytest.approx(-(0.53 - 0.24))
    assert (pose.y, pose.yaw) == (0.0, math.pi)


@pytest.mark.parametrize('beta1, beta2', [(0.0, 0.0), (0.4, -0.7), (-0.9, 1.2)])
def test_the_fin_frame_is_the_body_wave_at_plate_v(beta1, beta2):
    fin = tail_frames(beta1, beta2, GEOMETRY)[Frame.FIN]
    x, y = body_positions(np.array([GEOMETRY.l1 + GEOMETRY.l2]), beta1, beta2, GEOMETRY)
    assert (fin.x, fin.y) == pytest.approx((float(x[0]), float(y[0])), abs=1e-12)
    assert fin.yaw == pytest.approx(beta1 + beta2)


def test_a_straight_tail_puts_the_frames_on_the_axis_at_their_stations():
    frames = tail_frames(0.0, 0.0, GEOMETRY)
    assert [frames[f].x for f in (Frame.PLATE_II, Frame.PLATE_III, Frame.FIN)] == \
        pytest.approx([0.04, 0.08, 0.18])
    assert all(p.y == 0.0 and p.yaw == 0.0 for p in frames.values())


def test_dead_reckoning_moves_along_the_heading():
    pose = dead_reckoned(PlanarPose(1.0, 2.0, 0.0), math.pi / 2, 0.3, 2.0)
    assert (pose.x, pose.y, pose.yaw) == pytest.approx((1.0, 2.6, math.pi / 2))


@pytest.mark.parametrize('yaw', [0.0, 1.0, -2.5, 3.1])
def test_yaw_survives_a_quaternion(yaw):
    assert quaternion_yaw(*yaw_quaternion(yaw)) == pytest.approx(yaw)
