# SPDX-License-Identifier: Apache-2.0
"""
The kinematics node's output messages (message types only, no rclpy).

Every message is in frame ``FRAME`` = ``tail_base`` (the paper's C0, see the README), or the
``frame_id`` given (``fish_1/tail_base``: the node's frame_prefix).
body_wave_markers: id 0 the tail (LINE_STRIP), id 1 the desired wave (POINTS; a DELETE while it
is unknown, so RViz drops a stale overlay), id 2 O1 (sphere), id 3 O2 (cube).
"""

from __future__ import annotations

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point
import numpy as np
from visualization_msgs.msg import Marker, MarkerArray
from wirefish_kinematics.lighthill import SpeedEstimate
from wirefish_kinematics.tail_shape import TailShape
from wirefish_msgs.msg import BodyWave, SpeedEstimate as SpeedEstimateMsg

FRAME = 'tail_base'
MARKER_NAMESPACE = 'body_wave'


def to_stamp(sec: int, nanosec: int) -> Time:
    """Return a builtin_interfaces/Time."""
    return Time(sec=int(sec), nanosec=int(nanosec))


def body_wave_message(shape: TailShape, y_desired: np.ndarray | None, stamp: Time,
                      frame_id: str = FRAME) -> BodyWave:
    """Return the BodyWave of ``shape``; ``y_desired`` (S,) m empty while unknown."""
    msg = BodyWave(q=shape.stations.tolist(), x=shape.x.tolist(), y=shape.y.tolist(),
                   y_desired=[] if y_desired is None else y_desired.tolist(),
                   beta1=shape.beta1, beta2=shape.beta2, theta1=shape.theta1,
                   theta2=shape.theta2)
    msg.header.stamp, msg.header.frame_id = stamp, frame_id
    return msg


def speed_estimate_message(estimate: SpeedEstimate, stamp: Time,
                           frame_id: str = FRAME) -> SpeedEstimateMsg:
    """Return ``estimate`` (eqs 16-22) as a wirefish_msgs/SpeedEstimate."""
    msg = SpeedEstimateMsg(speed=estimate.speed, thrust=estimate.thrust, drag=estimate.drag,
                           swimming_number=estimate.swimming_number,
                           tail_beat_hz=estimate.tail_beat_hz,
                           tail_tip_amplitude=float(estimate.tail_tip_amplitude))
    msg.header.stamp, msg.header.frame_id = stamp, frame_id
    return msg


def _marker(stamp: Time, marker_id: int, kind: int, points_x: np.ndarray, points_y: np.ndarray,
            scale: float, rgb: tuple[float, float, float], frame_id: str) -> Marker:
    m = Marker(ns=MARKER_NAMESPACE, id=marker_id, type=kind, action=Marker.ADD)
    m.header.stamp, m.header.frame_id = stamp, frame_id
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = scale
    m.color.r, m.color.g, m.color.b = rgb
    m.color.a = 1.0
    m.points = [Point(x=float(px), y=float(py)) for px, py in zip(points_x, points_y)]
    return m


def body_wave_markers(shape: TailShape, y_desired: np.ndarray | None, stamp: Time,
                      frame_id: str = FRAME) -> MarkerArray:
    """Return the RViz markers of ``shape`` and of the desired wave (see the module doc)."""
    markers = [
        _marker(stamp, 0, Marker.LINE_STRIP, shape.x, shape.y, 0.004, (0.1, 0.3, 0.9),
                frame_id),
        _marker(stamp, 2, Marker.SPHERE_LIST, shape.ends_x[:1], shape.ends_y[:1], 0.012,
                (0.9, 0.5, 0.1), frame_id),
        _marker(stamp, 3, Marker.CUBE_LIST, shape.ends_x[1:], shape.ends_y[1:], 0.012,
                (0.8, 0.1, 0.1), frame_id)]
    if y_desired is None:
        gone = Marker(ns=MARKER_NAMESPACE, id=1, action=Marker.DELETE)
        gone.header.stamp, gone.header.frame_id = stamp, frame_id
        markers.append(gone)
    else:
        markers.append(_marker(stamp, 1, Marker.POINTS, shape.stations, y_desired, 0.004,
                               (0.2, 0.7, 0.2), frame_id))
    return MarkerArray(markers=markers)
