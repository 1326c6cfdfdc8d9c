# SPDX-License-Identifier: Apache-2.0
"""
The fish as a URDF (pure: no rclpy): the robot model RViz and Foxglove draw on the TF tree.

Links are the frames of ``frames`` below ``odom`` (``odom`` is the world the fish swims in,
REP-105, not part of the robot): ``base_link`` (the head), ``imu_link``, ``tail_base`` (oval
plate I), ``tail_plate_ii``, ``tail_plate_iii`` and ``caudal_fin`` (plate V and the fin).
Joints: ``imu_link`` and ``tail_base`` are fixed where tf_node's /tf_static puts them; the
three tail frames are planar joints about z (their poses come from tf_node's /tf, eqs 7-15),
placed at their stations on the straight body. Dimensions:

- the head: the paper's body, 530 (L) x 106 (W) x 150 (H) mm (section 2.1), from the nose to
  plate I (``body_length - l1 - l2 - l3``), as a box;
- plates I-V: oval, "decreasing in turn" (section 2.1, Fig. 1), sizes not given: each drawn as
  a thin elliptic cylinder-like box whose width and height fall linearly from the head's
  section at plate I to ``PLATE_V_FRACTION`` of it at plate V (an estimate);
- the spine between two frames: a thin box along the frame's x, as long as the arc to the next
  frame (l1 / 2, l1 / 2, l2);
- the caudal fin: rigid, ``l3`` long, ``fin_span`` high (the geometry block's estimate), thin.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

from wirefish_kinematics.geometry import FishGeometry
from wirefish_tf.frames import (Frame, PLATE_II_FRACTION, tail_base_in_base_link,
                                tail_frame_stations)

BODY_WIDTH, BODY_HEIGHT = 0.106, 0.150  # m, paper section 2.1
PLATE_THICKNESS = 0.004  # m, estimate
SPINE_SECTION = 0.008  # m, estimate: the drawn spine's width and height
FIN_THICKNESS = 0.004  # m, estimate
PLATE_V_FRACTION = 0.4  # plate V's section relative to plate I's, estimate
MODEL_LINKS = (Frame.BASE_LINK, Frame.IMU_LINK, Frame.TAIL_BASE, Frame.PLATE_II,
               Frame.PLATE_III, Frame.FIN)
_GREY, _BLUE, _ORANGE = ('grey', '0.6 0.6 0.65 1'), ('blue', '0.2 0.4 0.9 1'), (
    'orange', '0.9 0.45 0.1 1')


def _box(x: float, size: tuple[float, float, float], colour: tuple[str, str]) -> str:
    return (f'    <visual>\n      <origin xyz="{x:.6g} 0 0" rpy="0 0 0"/>\n'
            f'      <geometry><box size="{size[0]:.6g} {size[1]:.6g} {size[2]:.6g}"/></geometry>\n'
            f'      <material name="{colour[0]}"/>\n    </visual>\n')


def _plate(fraction: float) -> tuple[float, float, float]:
    """Return a plate's box at ``fraction`` of the way from plate I (0) to plate V (1)."""
    scale = 1.0 - (1.0 - PLATE_V_FRACTION) * fraction
    return PLATE_THICKNESS, BODY_WIDTH * scale, BODY_HEIGHT * scale


def fish_urdf(geometry: FishGeometry, imu: tuple[float, float, float] = (-0.12, 0.0, 0.0)
              ) -> str:
    """Return the URDF of a fish of ``geometry`` with its IMU at ``imu`` in base_link (m)."""
    head_length = geometry.body_length - geometry.tail_length
    stations = tail_frame_stations(geometry)
    links_span = geometry.l1 + geometry.l2
    spine = {Frame.TAIL_BASE: stations[Frame.PLATE_II],
             Frame.PLATE_II: stations[Frame.PLATE_III] - stations[Frame.PLATE_II],
             Frame.PLATE_III: stations[Frame.FIN] - stations[Frame.PLATE_III]}
    fraction = {Frame.TAIL_BASE: 0.0, Frame.PLATE_III: geometry.l1 / links_span,
                Frame.PLATE_II: PLATE_II_FRACTION * geometry.l1 / links_span, Frame.FIN: 1.0}
    visuals = {
        Frame.BASE_LINK: _box(-head_length / 2, (head_length, BODY_WIDTH, BODY_HEIGHT), _GREY),
        Frame.IMU_LINK: '',
        Frame.FIN: _box(0.0, _plate(1.0), _BLUE) + _box(
            geometry.l3 / 2, (geometry.l3, FIN_THICKNESS, geometry.fin_span), _ORANGE),
    }
    for frame, length in spine.items():
        visuals[frame] = _box(0.0, _plate(fraction[frame]), _BLUE) + _box(
            length / 2, (length, SPINE_SECTION, SPINE_SECTION), _BLUE)
    tail_base = tail_base_in_base_link(geometry)
    joints = [
        ('fixed', Frame.BASE_LINK, Frame.IMU_LINK, f'{imu[0]:.6g} {imu[1]:.6g} {imu[2]:.6g}',
         '0 0 0'),
        ('fixed', Frame.BASE_LINK, Frame.TAIL_BASE, f'{tail_base.x:.6g} 0 0',
         f'0 0 {tail_base.yaw:.9g}'),
    ] + [('planar', Frame.TAIL_BASE, frame, f'{stations[frame]:.6g} 0 0', '0 0 0')
         for frame in (Frame.PLATE_II, Frame.PLATE_III, Frame.FIN)]
    parts = ['<?xml version="1.0"?>\n',
             '<!-- The wire-driven elastic robotic fish: wirefish_tf.model (fish_urdf). -->\n',
             '<robot name="wirefish">\n']
    for name, rgba in (_GREY, _BLUE, _ORANGE):
        parts.append(f'  <material name="{name}"><color rgba="{rgba}"/></material>\n')
    for link in MODEL_LINKS:
        parts.append(f'  <link name={quoteattr(link.value)}>\n{visuals[link]}  </link>\n')
    for kind, parent, child, xyz, rpy in joints:
        parts.append(
            f'  <joint name="{child.value}_joint" type="{kind}">\n'
            f'    <parent link="{parent.value}"/>\n    <child link="{child.value}"/>\n'
            f'    <origin xyz="{xyz}" rpy="{rpy}"/>\n'
            + ('    <axis xyz="0 0 1"/>\n' if kind == 'planar' else '')
            + '  </joint>\n')
    parts.append('</robot>\n')
    return ''.join(parts)


def main() -> None:
    """
    Print the URDF of the default fish (the shipped urdf/wirefish.urdf).

    FishGeometry's defaults are config/wirefish.yaml's values; test/tf/test_robot_model.py
    holds the shipped file to the params file's geometry.
    """
    print(fish_urdf(FishGeometry()), end='')


if __name__ == '__main__':
    main()
