# SPDX-License-Identifier: Apache-2.0
"""
bridge_node's servo_trim on the wire, against a fish the test plays on a pty.

The link-up READs of both servos stop once each is reported; an invalid request sends nothing;
a valid one is resent until the ACK and the report answer it; the fish's NOT_NOW comes back
with the command that switches the bridge to stream mode.
"""

import math
import time

import pytest
from wirefish_bridge.protocol import (Ack, CalibrationSource, ErrorCode, MsgType, ServoTrim,
                                      ServoTrimReport, TrimOp)
from wirefish_msgs.srv import ServoTrim as ServoTrimSrv

pytestmark = pytest.mark.ros


def _report(servo: int, source=CalibrationSource.DEFAULTS, neutral: float = 1500.0,
            per_rad: float = 636.5) -> ServoTrimReport:
    return ServoTrimReport(servo, source, 1, neutral, per_rad, 500.0, 2500.0)


def _call(probe, fake_device, request, answer, timeout_s: float = 10.0):
    """Call servo_trim while the fish answers each SERVO_TRIM with ``answer(seq, trim, n)``."""
    client = probe.node.create_client(ServoTrimSrv, 'servo_trim')
    deadline = time.monotonic() + timeout_s
    while not client.service_is_ready() and time.monotonic() < deadline:
        fake_device.send_fish_heartbeat()
        probe.spin_for(0.1)
    future = client.call_async(request)
    sent: list[ServoTrim] = []
    while not future.done() and time.monotonic() < deadline:
        fake_device.send_fish_heartbeat()
        probe.spin_for(0.02)
        for frame in fake_device.decoder.feed(fake_device.read_available()):
            if isinstance(frame.message, ServoTrim):
                sent.append(frame.message)
                fake_device.send(*answer(frame.seq, frame.message, len(sent)))
    probe.node.destroy_client(client)
    assert future.done(), f'servo_trim did not answer; sent {sent}'
    return future.result(), sent


def _linked_and_read(probe, fake_device, start_bridge) -> None:
    """Start the bridge; answer its link-up READs until both servos are reported."""
    start_bridge(fake_device.link, 'gait_resend_s:=0.2')
    reported: set[int] = set()
    deadline = time.monotonic() + 20.0
    while reported != {1, 2} and time.monotonic() < deadline:
        fake_device.send_fish_heartbeat()
        probe.spin_for(0.05)
        for frame in fake_device.decoder.feed(fake_device.read_available()):
            if isinstance(frame.message, ServoTrim) and frame.message.op == TrimOp.READ:
                servo = frame.message.servo
                fake_device.send(Ack(MsgType.SERVO_TRIM, frame.seq, 0), _report(servo))
                reported.add(servo)
    assert reported == {1, 2}


def test_invalid_requests_send_nothing_and_a_valid_one_is_resent_until_answered(
        fake_device, start_bridge, probe):
    _linked_and_read(probe, fake_device, start_bridge)
    invalid = [ServoTrimSrv.Request(servo=1, op=1, direction=1, neutral_us=math.nan,
                                    us_per_rad=600.0),
               ServoTrimSrv.Request(servo=3, op=0),
               ServoTrimSrv.Request(servo=2, op=2, direction=0, neutral_us=1500.0,
                                    us_per_rad=600.0)]
    for request in invalid:
        response, sent = _call(probe, fake_device, request, lambda *_: [])
        assert not response.accepted and response.reason and sent == [], (response, sent)

    def second_copy_answered(seq, trim, n):   # the first copy (or its answer) is lost
        if n < 2:
            return []
        return [Ack(MsgType.SERVO_TRIM, seq, 0),
                _report(1, CalibrationSource.LIVE, trim.neutral_us, trim.us_per_rad)]

    response, sent = _call(probe, fake_device, ServoTrimSrv.Request(
        servo=1, op=1, direction=1, neutral_us=1550.0, us_per_rad=600.0), second_copy_answered)
    print(f'valid SET: {len(sent)} copies, accepted {response.accepted} {response.reason!r}')
    assert sent == [ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0)] * 2
    assert response.accepted and response.calibration.source == 2
    assert (response.calibration.neutral_us, response.calibration.us_per_rad) == (1550.0, 600.0)


def test_not_now_comes_back_with_how_to_switch_to_stream_mode(fake_device, start_bridge, probe):
    _linked_and_read(probe, fake_device, start_bridge)
    response, sent = _call(probe, fake_device, ServoTrimSrv.Request(servo=2, op=3),
                           lambda seq, *_: [Ack(MsgType.SERVO_TRIM, seq, ErrorCode.NOT_NOW)])
    assert sent == [ServoTrim(2, TrimOp.FACTORY)]
    assert not response.accepted
    assert 'ros2 param set /bridge_node drive_mode stream' in response.reason
    assert response.calibration.servo == 2   # the last report of it: the link-up READ's
