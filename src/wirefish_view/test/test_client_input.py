# SPDX-License-Identifier: Apache-2.0
"""A client's cmd_vel is accepted within the drive limits; everything else is refused."""

import json
import math

import pytest
from wirefish_view.client_input import check_advertised, cmd_vel_from_client, CmdVel
from wirefish_view.errors import RefusedInput

TOPIC = '/wirefish/cmd_vel'


def _json(linear_x=0.0, angular_z=0.0, **extra) -> bytes:
    return json.dumps({'linear': {'x': linear_x, **extra}, 'angular': {'z': angular_z}}).encode()


def test_a_twist_within_the_limits_is_accepted():
    assert cmd_vel_from_client('json', _json(0.2, -0.3), 0.4, 0.6) == CmdVel(0.2, -0.3)


@pytest.mark.parametrize('data', [
    _json(0.5), _json(-0.1), _json(0.1, 0.7), _json(math.nan), _json(0.1, y=0.2),
    b'{"linear": 3}', b'\x00\x01not json', b'[]'])
def test_a_bad_twist_is_refused(data):
    with pytest.raises(RefusedInput):
        cmd_vel_from_client('json', data, 0.4, 0.6)


def test_corrupt_cdr_is_refused():
    with pytest.raises(RefusedInput):
        cmd_vel_from_client('cdr', b'\x00\x01\x00\x00\x01', 0.4, 0.6)


@pytest.mark.parametrize('topic, encoding, schema', [
    ('/wirefish/servo_cmd', 'json', 'geometry_msgs/msg/Twist'),
    (TOPIC, 'protobuf', 'geometry_msgs/msg/Twist'),
    (TOPIC, 'json', 'sensor_msgs/msg/JointState')])
def test_any_other_channel_is_refused(topic, encoding, schema):
    with pytest.raises(RefusedInput):
        check_advertised(topic, encoding, schema, TOPIC)


def test_the_cmd_vel_channel_is_accepted():
    check_advertised(TOPIC, 'cdr', 'geometry_msgs/Twist', TOPIC)
