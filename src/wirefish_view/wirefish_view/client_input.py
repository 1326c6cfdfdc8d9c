# SPDX-License-Identifier: Apache-2.0
"""
What a view client may send: cmd_vel only, validated (pure: no rclpy but its serializer).

A client advertises a channel (topic, encoding, schema name) before it publishes. Only the
graph's ``cmd_vel`` as ``geometry_msgs/msg/Twist`` is accepted, in CDR (the Foxglove app's
teleop panel) or JSON (the dashboard): forward speed linear.x in [0, max_speed] m/s, yaw rate
angular.z in [-max_turn, max_turn] rad/s (the limits of `wirefish drive`), every other field
0. Anything else raises ``RefusedInput`` with the reason; nothing is published then.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import math

from wirefish_view.errors import Refusal, RefusedInput

TWIST = 'geometry_msgs/msg/Twist'
ENCODINGS = ('cdr', 'json')
_AXES = ('x', 'y', 'z')


@dataclass(frozen=True)
class CmdVel:
    """A validated drive command: forward speed (m/s) and yaw rate (rad/s, + left)."""

    speed: float
    turn: float


def check_advertised(topic: str, encoding: str, schema_name: str, cmd_vel_topic: str) -> None:
    """Raise ``RefusedInput`` unless a client channel is ``cmd_vel_topic`` as a Twist."""
    if topic != cmd_vel_topic:
        raise RefusedInput(f'client publish on {topic!r} refused: only {cmd_vel_topic} is '
                           'accepted', Refusal.CHANNEL)
    if encoding not in ENCODINGS:
        raise RefusedInput(f'client publish on {topic} in {encoding!r} refused: use '
                           f'{" or ".join(ENCODINGS)}', Refusal.CHANNEL)
    if schema_name.replace('/msg/', '/') != TWIST.replace('/msg/', '/'):
        raise RefusedInput(f'client publish on {topic} as {schema_name!r} refused: it is a '
                           f'{TWIST}', Refusal.CHANNEL)


def _twist_fields(encoding: str, data: bytes) -> tuple[list[float], list[float]]:
    if encoding == 'json':
        try:
            message = json.loads(data)
            linear = [float(message.get('linear', {}).get(a, 0.0)) for a in _AXES]
            angular = [float(message.get('angular', {}).get(a, 0.0)) for a in _AXES]
        except (ValueError, TypeError, AttributeError) as error:
            raise RefusedInput(f'cmd_vel: not a Twist in JSON ({error})') from error
        return linear, angular
    from geometry_msgs.msg import Twist
    from rclpy.serialization import deserialize_message
    try:
        twist = deserialize_message(bytes(data), Twist)
    except Exception as error:  # the C deserializer raises a bare RuntimeError-like error
        raise RefusedInput(f'cmd_vel: not a CDR Twist ({len(data)} bytes)') from error
    return ([twist.linear.x, twist.linear.y, twist.linear.z],
            [twist.angular.x, twist.angular.y, twist.angular.z])


def cmd_vel_from_client(encoding: str, data: bytes, max_speed: float, max_turn: float
                        ) -> CmdVel:
    """Return the validated command in ``data``; raise ``RefusedInput`` with the reason."""
    linear, angular = _twist_fields(encoding, data)
    if not all(math.isfinite(v) for v in (*linear, *angular)):
        raise RefusedInput('cmd_vel: every field must be finite')
    if any(linear[1:]) or any(angular[:2]):
        raise RefusedInput('cmd_vel: only linear.x and angular.z may be non-zero',
                           Refusal.OUT_OF_LIMITS)
    speed, turn = linear[0], angular[2]
    if not 0.0 <= speed <= max_speed:
        raise RefusedInput(f'cmd_vel: linear.x must be in [0, {max_speed:g}] m/s, got {speed:g}',
                           Refusal.OUT_OF_LIMITS)
    if abs(turn) > max_turn:
        raise RefusedInput(f'cmd_vel: angular.z must be in [-{max_turn:g}, {max_turn:g}] '
                           f'rad/s, got {turn:g}', Refusal.OUT_OF_LIMITS)
    return CmdVel(speed, turn)
