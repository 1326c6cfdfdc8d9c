# SPDX-License-Identifier: Apache-2.0
"""
tf_node: the fish's TF tree (REP-105) on ``/tf`` and ``/tf_static``; frames in ``frames``.

Subscribes
    ``body_wave`` (wirefish_msgs/BodyWave, sensor data): its bend angles place the moving tail
    frames (``tail_plate_ii``, ``tail_plate_iii``, ``caudal_fin`` in ``tail_base``), stamped
    as the body wave, at its rate.
    ``sim/ground_truth`` (nav_msgs/Odometry, reliable): the virtual fish's pose, published as
    ``odom`` -> ``base_link`` unchanged (same stamp).
    ``imu/data`` (sensor_msgs/Imu, sensor data) and ``speed_estimate``
    (wirefish_msgs/SpeedEstimate, reliable): the real fish's odometry, dead-reckoned
    (``frames.dead_reckoned``: the speed estimate along the IMU yaw, drifting as dead reckoning
    does), at most ``odom_rate_hz``.
Publishes
    ``/tf`` (tf2_msgs/TFMessage, reliable depth 100, as tf2's broadcaster) and ``/tf_static``
    (reliable, transient local: ``base_link`` -> ``imu_link``, ``base_link`` -> ``tail_base``,
    again whenever the geometry changes); ``robot_description`` (std_msgs/String, the fish's
    URDF from ``model.fish_urdf``, reliable and transient local as robot_state_publisher
    publishes it; link names without the frame prefix, as robot_state_publisher keeps them;
    again whenever the geometry changes).
Parameters: ``odom_source`` (``auto``: ground truth once sim/ground_truth is heard, dead
reckoning until then; ``ground_truth``; ``dead_reckoning``), ``odom_rate_hz``, ``imu_x``,
``imu_y``, ``imu_z`` (the IMU in base_link, m), the geometry (l1, l2, l3, body_length: the
graph's ``/**`` block) and ``frame_prefix``; the table is ``tf_node_parameters``.
"""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Imu
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage
from wirefish_common.frames import declare_frame_prefix, prefixed
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import LATCHED, RELIABLE, reliable, SENSOR_DATA, TF, TF_STATIC
from wirefish_kinematics.geometry_parameters import geometry_from
from wirefish_msgs.msg import BodyWave, SpeedEstimate
from wirefish_tf.frames import (dead_reckoned, Frame, OdomSource, PlanarPose, quaternion_yaw,
                                tail_base_in_base_link, tail_frames)
from wirefish_tf.model import fish_urdf
from wirefish_tf.tf_messages import tf_message, transform
from wirefish_tf.tf_node_parameters import GEOMETRY_NAMES, TABLE


# A second of the virtual fish's 50 Hz ground truth: a tf_node starved for a moment on a
# loaded machine publishes every pose late rather than drop the oldest (depth 10 kept 0.2 s).
GROUND_TRUTH_QOS = reliable(depth=50)


def _seconds(stamp: Time) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


class TfNode(Node):
    """Publishes the fish's frames: odometry, the static mounts and the moving tail."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters; wire /tf, /tf_static and the subscriptions."""
        super().__init__('tf_node', **kwargs)
        self._node_parameters = NodeParameters(self, TABLE, self._apply)
        prefix = declare_frame_prefix(self)
        self._frame = {frame: prefixed(prefix, frame.value) for frame in Frame}
        self._values = self._node_parameters.values  # live: a set is in it before _apply
        self._geometry = geometry_from(self._values, GEOMETRY_NAMES)
        self._source = OdomSource(self._values['odom_source'])
        self._heard_ground_truth = False
        self._pose = PlanarPose(0.0, 0.0, 0.0)
        self._yaw: float | None = None
        self._speed = 0.0
        self._last_imu_s: float | None = None
        self._last_odom_s = -math.inf
        self._tf_pub = self.create_publisher(TFMessage, '/tf', TF)
        self._static_pub = self.create_publisher(TFMessage, '/tf_static', TF_STATIC)
        self._description_pub = self.create_publisher(String, 'robot_description', LATCHED)
        self.create_subscription(BodyWave, 'body_wave', self._on_body_wave, SENSOR_DATA)
        self.create_subscription(Odometry, 'sim/ground_truth', self._on_ground_truth,
                                 GROUND_TRUTH_QOS)
        self.create_subscription(Imu, 'imu/data', self._on_imu, SENSOR_DATA)
        self.create_subscription(SpeedEstimate, 'speed_estimate', self._on_speed, RELIABLE)
        self._publish_static()

    # --- parameters -----------------------------------------------------------------------
    def _apply(self, names: frozenset[str]) -> None:
        self._geometry = geometry_from(self._values, GEOMETRY_NAMES)
        self._source = OdomSource(self._values['odom_source'])
        if names & {*GEOMETRY_NAMES, 'imu_x', 'imu_y', 'imu_z'}:
            self._publish_static()

    # --- static mounts --------------------------------------------------------------------
    def _publish_static(self) -> None:
        stamp = self.get_clock().now().to_msg()
        base = self._frame[Frame.BASE_LINK]
        imu = PlanarPose(self._values['imu_x'], self._values['imu_y'], 0.0,
                         self._values['imu_z'])
        self._static_pub.publish(tf_message([
            transform(base, self._frame[Frame.IMU_LINK], imu, stamp),
            transform(base, self._frame[Frame.TAIL_BASE],
                      tail_base_in_base_link(self._geometry), stamp)]))
        self._description_pub.publish(String(data=fish_urdf(
            self._geometry, (imu.x, imu.y, imu.z))))

    # --- the moving tail ------------------------------------------------------------------
    def _on_body_wave(self, msg: BodyWave) -> None:
        if not (math.isfinite(msg.beta1) and math.isfinite(msg.beta2)):
            return  # the kinematics never sends these; nothing to place
        parent = self._frame[Frame.TAIL_BASE]
        poses = tail_frames(msg.beta1, msg.beta2, self._geometry)
        self._tf_pub.publish(tf_message([
            transform(parent, self._frame[frame], pose, msg.header.stamp)
            for frame, pose in poses.items()]))

    # --- odometry -------------------------------------------------------------------------
    def _on_ground_truth(self, msg: Odometry) -> None:
        if self._source is OdomSource.DEAD_RECKONING:
            return
        if not self._heard_ground_truth:
            self._heard_ground_truth = True
            if self._source is OdomSource.AUTO:
                self.get_logger().info('odom -> base_link from sim/ground_truth (virtual fish)')
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        values = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
        if not all(math.isfinite(v) for v in values):
            return
        out = transform(self._frame[Frame.ODOM], self._frame[Frame.BASE_LINK],
                        PlanarPose(p.x, p.y, 0.0, p.z), msg.header.stamp)
        out.transform.rotation = q  # the simulated attitude as published
        self._tf_pub.publish(tf_message([out]))

    def _dead_reckoning(self) -> bool:
        return (self._source is OdomSource.DEAD_RECKONING
                or (self._source is OdomSource.AUTO and not self._heard_ground_truth))

    def _on_speed(self, msg: SpeedEstimate) -> None:
        if math.isfinite(msg.speed) and msg.speed >= 0.0:
            self._speed = msg.speed

    def _on_imu(self, msg: Imu) -> None:
        if not self._dead_reckoning():
            return
        q = msg.orientation
        if not all(math.isfinite(v) for v in (q.x, q.y, q.z, q.w)) or (
                q.x == q.y == q.z == q.w == 0.0):
            return
        now_s = _seconds(msg.header.stamp)
        yaw = quaternion_yaw(q.x, q.y, q.z, q.w)  # imu_link is aligned with base_link
        if self._last_imu_s is not None and self._yaw is not None and now_s > self._last_imu_s:
            self._pose = dead_reckoned(self._pose, self._yaw, self._speed,
                                       now_s - self._last_imu_s)
        self._pose = PlanarPose(self._pose.x, self._pose.y, yaw)
        self._last_imu_s, self._yaw = now_s, yaw
        # At most odom_rate_hz (a hair early counts: 100 Hz samples give 50 Hz, not 33).
        if now_s - self._last_odom_s >= 0.999 / self._values['odom_rate_hz']:
            self._last_odom_s = now_s
            self._tf_pub.publish(tf_message([transform(
                self._frame[Frame.ODOM], self._frame[Frame.BASE_LINK], self._pose,
                msg.header.stamp)]))


def main(args: list[str] | None = None) -> None:
    """Run the TF node until shutdown."""
    run_node(TfNode, args)
