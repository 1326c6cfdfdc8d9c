# SPDX-License-Identifier: Apache-2.0
"""The kinematics node's messages: body wave, speed estimate and RViz markers, in tail_base."""

from builtin_interfaces.msg import Time
import numpy as np
import pytest
from visualization_msgs.msg import Marker
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.kinematics_messages import (body_wave_markers, body_wave_message,
                                                     FRAME, speed_estimate_message)
from wirefish_kinematics.lighthill import SpeedEstimate
from wirefish_kinematics.tail_shape import tail_shape

SHAPE = tail_shape((0.3, -0.2), FishGeometry(), 6)
STAMP = Time(sec=12, nanosec=345)
Y_DESIRED = np.linspace(0.0, 0.01, 6)


def test_the_frame_is_the_papers_c0():
    assert FRAME == 'tail_base'


@pytest.mark.parametrize('y_desired, expected', [(None, []), (Y_DESIRED, Y_DESIRED.tolist())])
def test_the_body_wave_carries_the_shape_and_the_desired_wave(y_desired, expected):
    msg = body_wave_message(SHAPE, y_desired, STAMP)
    assert (list(msg.q), list(msg.x), list(msg.y)) == (
        SHAPE.stations.tolist(), SHAPE.x.tolist(), SHAPE.y.tolist())
    assert list(msg.y_desired) == expected
    assert (msg.beta1, msg.beta2, msg.theta1, msg.theta2) == (
        SHAPE.beta1, SHAPE.beta2, SHAPE.theta1, SHAPE.theta2)
    assert (msg.header.stamp, msg.header.frame_id) == (STAMP, FRAME)


def test_the_speed_estimate_carries_every_figure():
    estimate = SpeedEstimate(0.39, 1.5, 1.5, 0.245, 3.0, np.float64(0.0885))
    msg = speed_estimate_message(estimate, STAMP)
    assert (msg.speed, msg.thrust, msg.drag, msg.swimming_number, msg.tail_beat_hz,
            msg.tail_tip_amplitude) == (0.39, 1.5, 1.5, 0.245, 3.0, 0.0885)
    assert (msg.header.stamp, msg.header.frame_id) == (STAMP, FRAME)


def test_the_markers_show_tail_link_ends_and_desired_wave():
    markers = {m.id: m for m in body_wave_markers(SHAPE, Y_DESIRED, STAMP).markers}
    assert {i: m.type for i, m in markers.items()} == {
        0: Marker.LINE_STRIP, 1: Marker.POINTS, 2: Marker.SPHERE_LIST, 3: Marker.CUBE_LIST}
    assert [(p.x, p.y) for p in markers[0].points] == list(zip(SHAPE.x, SHAPE.y))
    assert [p.y for p in markers[1].points] == Y_DESIRED.tolist()
    assert (markers[2].points[0].x, markers[3].points[0].x) == tuple(SHAPE.ends_x)
    assert all(m.header.frame_id == FRAME and m.header.stamp == STAMP for m in markers.values())


def test_an_unknown_desired_wave_deletes_its_marker():
    markers = {m.id: m for m in body_wave_markers(SHAPE, None, STAMP).markers}
    assert markers[1].action == Marker.DELETE
