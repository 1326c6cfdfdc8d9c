# SPDX-License-Identifier: Apache-2.0
"""
The fish's two servos as a sensor_msgs/JointState: one set of joint names, one conversion each way.

Writing: ``servo_joint_state`` names the joints ``SERVO_JOINTS`` (``servo_1``, ``servo_2``),
positions in rad, velocities in rad/s when known (else the velocity array stays empty, as the
message definition allows).

Reading (``servo_angles``, ``servo_sample``): the joints are found by name, in any order, among
any other joints; ``position`` must have one entry per name; ``velocity`` is used when it has one
entry per name (otherwise the rates are unknown, NaN); every value used must be finite.

Unnamed positions are refused. sensor_msgs/JointState says the arrays share the ``name`` order;
without names, "the first two positions" is a guess about who published, and the cost of a wrong
guess is a servo driven by some other joint's angle (any JointState publisher remapped onto
``servo_cmd``, e.g. a joint-state GUI for another robot). Every publisher in the graph names its
joints, so the strict rule costs nothing; a hand-typed ``ros2 topic pub`` must name them too.
Every reader of servo angles (the bridge, the kinematics) applies this one rule.

Message types only (no rclpy node), so it is testable without a ROS graph. The readers take a
JointState or what a raw intake reads from its bytes (``cdr_views.JointStateView``: the
same ``name``, ``position`` and ``velocity``).
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Sequence

from builtin_interfaces.msg import Time
from sensor_msgs.msg import JointState

SERVO_JOINTS: tuple[str, str] = ('servo_1', 'servo_2')

ServoPair = tuple[float, float]


@dataclass(frozen=True)
class JointProblem:
    """
    Why a JointState gives no servo pair.

    ``kind`` is one of ``'names'``, ``'size'``, ``'angles'``, ``'rates'`` (and ``'bytes'``: a
    raw intake's bytes were no JointState, ``cdr_views.CdrError``), so that a node can
    throttle each kind of warning separately (one bad source must not hide another).
    """

    kind: str
    message: str


def _indices(msg: JointState) -> list[int] | JointProblem:
    names = list(msg.name)
    if not all(joint in names for joint in SERVO_JOINTS):
        return JointProblem('names', f'JointState needs joints {SERVO_JOINTS}, got {names}')
    if len(msg.position) != len(names):
        return JointProblem('size', f'JointState has {len(msg.position)} positions for '
                            f'{len(names)} names')
    return [names.index(joint) for joint in SERVO_JOINTS]


def servo_angles(msg: JointState) -> ServoPair | JointProblem:
    """Return the positions (rad) of servo_1, servo_2 in ``msg``, or why there are none."""
    index = _indices(msg)
    if isinstance(index, JointProblem):
        return index
    angles = (float(msg.position[index[0]]), float(msg.position[index[1]]))
    if not all(math.isfinite(a) for a in angles):
        return JointProblem('angles', f'non-finite servo angles {angles}')
    return angles


def servo_sample(msg: JointState) -> tuple[ServoPair, ServoPair] | JointProblem:
    """
    Return (angles rad, rates rad/s) of servo_1, servo_2 in ``msg``, or why it is unusable.

    The rates are (NaN, NaN) when ``msg`` carries no velocity per name; given but non-finite
    rates make the sample unusable (a consumer would silently fall back otherwise).
    """
    angles = servo_angles(msg)
    if isinstance(angles, JointProblem):
        return angles
    if len(msg.velocity) != len(msg.name):
        return angles, (math.nan, math.nan)
    index = [list(msg.name).index(joint) for joint in SERVO_JOINTS]
    rates = (float(msg.velocity[index[0]]), float(msg.velocity[index[1]]))
    if not all(math.isfinite(r) for r in rates):
        return JointProblem('rates', f'non-finite servo rates {rates}')
    return angles, rates


def servo_joint_state(angles: Sequence[float], rates: Sequence[float] | None = None,
                      stamp: Time | None = None) -> JointState:
    """Return a JointState of servo_1, servo_2: ``angles`` (rad), ``rates`` (rad/s) if known."""
    if len(angles) != len(SERVO_JOINTS) or (rates is not None and len(rates) != len(angles)):
        raise ValueError(f'need one angle (and rate) per joint of {SERVO_JOINTS}, got '
                         f'angles {list(angles)} rates {rates}')
    msg = JointState()
    if stamp is not None:
        msg.header.stamp = stamp
    msg.name = list(SERVO_JOINTS)
    msg.position = [float(a) for a in angles]
    if rates is not None:
        msg.velocity = [float(r) for r in rates]
    return msg
