# SPDX-License-Identifier: Apache-2.0
"""
The fish as a Foxglove scene (foxglove.SceneUpdate): head, the tail's two arcs, fin, trail.

The head is a box at ``base_link``; the arcs L1 (plate I to III), L2 (III to V) and the rigid
fin (V to the tip) are line strips of the body wave's stations in ``tail_base``; the trail is
the fish's recent positions in ``odom``. The viewer places each by TF (/tf, /tf_static).
"""

from __future__ import annotations

from collections.abc import Sequence

from foxglove.messages import (Color, CubePrimitive, LinePrimitive, Point3, Pose, Quaternion,
                               SceneEntity, SceneUpdate, Timestamp, Vector3)

HEAD_SIZE = (0.29, 0.106, 0.15)  # the body ahead of plate I, as a box (m)
_IDENTITY = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
_ARC_COLOURS = (Color(r=0.1, g=0.3, b=0.9, a=1.0), Color(r=0.1, g=0.6, b=0.9, a=1.0),
                Color(r=0.9, g=0.4, b=0.1, a=1.0))


def _line(xs: Sequence[float], ys: Sequence[float], colour: Color) -> LinePrimitive:
    return LinePrimitive(thickness=0.006, points=[Point3(x=x, y=y, z=0.0) for x, y in zip(xs, ys)],
                         color=colour, pose=Pose(position=Vector3(x=0.0, y=0.0, z=0.0),
                                                 orientation=_IDENTITY))


def tail_segments(q: Sequence[float], x: Sequence[float], y: Sequence[float], l1: float,
                  l2: float) -> list[tuple[list[float], list[float]]]:
    """Return the stations of L1, L2 and the fin: [(xs, ys)] each, sharing their end points."""
    bounds = ((0.0, l1), (l1, l1 + l2), (l1 + l2, float('inf')))
    return [([xi for qi, xi in zip(q, x) if lo - 1e-9 <= qi <= hi + 1e-9],
             [yi for qi, yi in zip(q, y) if lo - 1e-9 <= qi <= hi + 1e-9]) for lo, hi in bounds]


def fish_scene(stamp_ns: int, frames: dict[str, str], segments: list[tuple[list[float],
               list[float]]], trail: Sequence[tuple[float, float]]) -> SceneUpdate:
    """Return the scene: ``frames`` maps base_link, tail_base, odom to this fish's frame ids."""
    stamp = Timestamp(sec=stamp_ns // 1_000_000_000, nsec=stamp_ns % 1_000_000_000)
    head = SceneEntity(timestamp=stamp, frame_id=frames['base_link'], id='head',
                       frame_locked=True, cubes=[CubePrimitive(
                           pose=Pose(position=Vector3(x=-HEAD_SIZE[0] / 2, y=0.0, z=0.0),
                                     orientation=_IDENTITY),
                           size=Vector3(x=HEAD_SIZE[0], y=HEAD_SIZE[1], z=HEAD_SIZE[2]),
                           color=Color(r=0.6, g=0.6, b=0.65, a=0.8))])
    tail = SceneEntity(timestamp=stamp, frame_id=frames['tail_base'], id='tail',
                       frame_locked=True,
                       lines=[_line(xs, ys, c) for (xs, ys), c in zip(segments, _ARC_COLOURS)
                              if len(xs) >= 2])
    entities = [head, tail]
    if len(trail) >= 2:
        entities.append(SceneEntity(timestamp=stamp, frame_id=frames['odom'], id='trail',
                                    lines=[_line([p[0] for p in trail], [p[1] for p in trail],
                                                 Color(r=0.2, g=0.7, b=0.3, a=1.0))]))
    return SceneUpdate(entities=entities)
