# SPDX-License-Identifier: Apache-2.0
"""The message registry of protocol.py: one class per type byte, nothing falls through."""

from dataclasses import dataclass

import pytest
from wirefish_bridge.codec import encode_frame
from wirefish_bridge.protocol import (Ack, ErrorReport, Gait, Health, Heartbeat, LinkConfig,
                                      message_class, message_type, MsgType, pack_payload,
                                      PAYLOAD_SIZES, ProtocolMessage, ServoCommand, ServoTrim,
                                      ServoTrimReport, Telemetry, TelemetryCompact,
                                      UnknownMessageError, unpack_payload)


@pytest.mark.parametrize('kind, cls, size', [   # the sizes of PROTOCOL.md's message table
    (MsgType.HEARTBEAT, Heartbeat, 6), (MsgType.LINK_CONFIG, LinkConfig, 9),
    (MsgType.ACK, Ack, 4), (MsgType.SERVO_CMD, ServoCommand, 8), (MsgType.GAIT, Gait, 42),
    (MsgType.TELEMETRY, Telemetry, 56), (MsgType.TELEMETRY_COMPACT, TelemetryCompact, 32),
    (MsgType.HEALTH, Health, 61), (MsgType.ERROR, ErrorReport, 3),
    (MsgType.SERVO_TRIM, ServoTrim, 12), (MsgType.SERVO_TRIM_REPORT, ServoTrimReport, 20),
])
def test_each_type_byte_has_its_one_class_and_documented_size(kind, cls, size):
    assert message_class(kind) is cls and cls.KIND is kind
    assert PAYLOAD_SIZES[kind] == size


@dataclass(frozen=True)
class NotAMessage:
    servo_1: float = 0.0
    servo_2: float = 0.0


@pytest.mark.parametrize('send', [message_type, pack_payload, lambda m: encode_frame(m, 0)])
def test_an_unregistered_object_is_refused_with_the_known_messages(send):
    with pytest.raises(UnknownMessageError, match='not a protocol message.*ServoCommand'):
        send(NotAMessage())


def test_a_second_class_for_a_registered_type_is_refused():
    with pytest.raises(ValueError, match='SERVO_CMD .* is already the message ServoCommand'):
        class Duplicate(ProtocolMessage, kind=MsgType.SERVO_CMD, layout='<ff'):
            pass
    assert message_class(MsgType.SERVO_CMD) is ServoCommand


def test_a_message_needs_a_type_byte_and_a_layout():
    with pytest.raises(TypeError):
        class Unregistered(ProtocolMessage):
            pass


@pytest.mark.parametrize('kind', [0x00, 0x04, 0x13, 0x55, 0xFF])
def test_an_unregistered_type_byte_decodes_to_nothing(kind):
    assert message_class(kind) is None
    assert unpack_payload(kind, bytes(PAYLOAD_SIZES[MsgType.ERROR])) is None
