# SPDX-License-Identifier: Apache-2.0
"""The TF messages of the fish's frames (message types only, no rclpy)."""

from __future__ import annotations

from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from wirefish_tf.frames import PlanarPose, yaw_quaternion


def transform(parent: str, child: str, pose: PlanarPose, stamp: Time) -> TransformStamped:
    """Return the TransformStamped placing ``child`` at ``pose`` in ``parent``."""
    msg = TransformStamped()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp, parent, child
    t = msg.transform.translation
    t.x, t.y, t.z = float(pose.x), float(pose.y), float(pose.z)
    r = msg.transform.rotation
    r.x, r.y, r.z, r.w = yaw_quaternion(pose.yaw)
    return msg


def tf_message(transforms: list[TransformStamped]) -> TFMessage:
    """Return one TFMessage carrying ``transforms``."""
    return TFMessage(transforms=transforms)
