# SPDX-License-Identifier: Apache-2.0
"""SERVO_TRIM and SERVO_TRIM_REPORT: their bytes, their enums, what the fish refuses."""

import math
import struct

import pytest
from wirefish_bridge.codec import encode_frame, StreamDecoder
from wirefish_bridge.protocol import (CalibrationSource, ErrorCode, MsgType, pack_payload,
                                      ServoTrim, ServoTrimReport, TrimOp, unpack_payload)


def test_the_new_codes_and_type_bytes_are_the_spec_s():
    assert (MsgType.SERVO_TRIM, MsgType.SERVO_TRIM_REPORT) == (0x12, 0x22)
    assert (ErrorCode.NOT_NOW, ErrorCode.STORAGE_FAILED) == (7, 8)
    assert [int(op) for op in TrimOp] == [0, 1, 2, 3]
    assert [int(s) for s in CalibrationSource] == [0, 1, 2]


def test_servo_trim_packs_servo_op_direction_reserved_then_two_floats():
    trim = ServoTrim(2, TrimOp.SAVE, -1, 1550.0, 600.0)
    assert pack_payload(trim) == struct.pack('<BBbBff', 2, 2, -1, 0, 1550.0, 600.0)
    assert len(pack_payload(trim)) == 12


def test_servo_trim_report_packs_its_twenty_bytes_in_the_spec_s_order():
    report = ServoTrimReport(1, CalibrationSource.STORED, -1, 1550.0, 600.0, 500.0, 2500.0)
    wire = pack_payload(report)
    assert wire == struct.pack('<BBbBffff', 1, 1, -1, 0, 1550.0, 600.0, 500.0, 2500.0)
    assert len(wire) == 20


def test_a_decoded_trim_and_report_give_their_enums_back():
    trim = unpack_payload(MsgType.SERVO_TRIM, struct.pack('<BBbBff', 1, 3, 0, 0, 0.0, 0.0))
    report = unpack_payload(MsgType.SERVO_TRIM_REPORT,
                            struct.pack('<BBbBffff', 2, 2, 1, 0, 1500.0, 636.5, 500.0, 2500.0))
    assert trim.op is TrimOp.FACTORY
    assert report.source is CalibrationSource.LIVE


@pytest.mark.parametrize('kind, layout, values', [
    (MsgType.SERVO_TRIM, '<BBbBff', (1, 1, 1, 0, math.nan, 600.0)),
    (MsgType.SERVO_TRIM, '<BBbBff', (1, 1, 1, 0, 1500.0, math.inf)),
    (MsgType.SERVO_TRIM_REPORT, '<BBbBffff', (1, 0, 1, 0, 1500.0, 636.0, -math.inf, 2500.0)),
])
def test_a_non_finite_float_decodes_to_nothing(kind, layout, values):
    assert unpack_payload(kind, struct.pack(layout, *values)) is None


def test_out_of_range_values_still_decode_as_the_fish_judges_them():
    wire = encode_frame(ServoTrim(3, 9, 0, 1500.0, -1.0, reserved=4), 5)
    (frame,) = StreamDecoder().feed(wire)
    assert frame.message == ServoTrim(3, 9, 0, 1500.0, -1.0, reserved=4)


@pytest.mark.parametrize('trim, words', [
    (ServoTrim(3, TrimOp.READ), 'servo 3'),
    (ServoTrim(0, TrimOp.READ), 'servo 0'),
    (ServoTrim(1, 4), 'op 4'),
    (ServoTrim(1, TrimOp.READ, reserved=1), 'reserved'),
    (ServoTrim(1, TrimOp.SET, 0, 1500.0, 600.0), 'direction 0'),
    (ServoTrim(1, TrimOp.SAVE, 2, 1500.0, 600.0), 'direction 2'),
    (ServoTrim(1, TrimOp.SET, 1, 1500.0, 0.0), 'us_per_rad 0'),
    (ServoTrim(1, TrimOp.SET, 1, math.nan, 600.0), 'finite'),
])
def test_each_refused_request_is_named(trim, words):
    assert words in trim.problem()


@pytest.mark.parametrize('trim', [
    ServoTrim(1, TrimOp.READ), ServoTrim(2, TrimOp.FACTORY),
    ServoTrim(2, TrimOp.SET, -1, 1550.0, 600.0), ServoTrim(1, TrimOp.SAVE, 1, 1500.0, 636.6),
])
def test_a_valid_request_has_no_problem(trim):
    assert trim.problem() is None
