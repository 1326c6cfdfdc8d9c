# SPDX-License-Identifier: Apache-2.0
"""Codec: round trips, streaming, resynchronisation and error counters."""

import math
import struct

from cobs import cobs
from hypothesis import given, settings, strategies as st
import pytest
from wirefish_bridge.codec import (crc16, DecoderStats, encode_body, encode_frame, FrameEncoder,
                                   MAX_BODY, MAX_ENCODED_FRAME, StreamDecoder)
from wirefish_bridge.protocol import (Ack, ClockSource, ErrorCode, ErrorReport, Gait, Health,
                                      Heartbeat, LinkConfig, message_class, MsgType,
                                      ResetCause, Role, ServoCommand, ServoTrim,
                                      ServoTrimReport, Status, Telemetry, TelemetryCompact)

f32 = st.floats(width=32, allow_nan=False, allow_infinity=False)
u8 = st.integers(0, 0xFF)
u16 = st.integers(0, 0xFFFF)
i16 = st.integers(-0x8000, 0x7FFF)
u32 = st.integers(0, 0xFFFFFFFF)
i8 = st.integers(-0x80, 0x7F)
# One strategy per registered message class (a test below keeps it complete).
STRATEGIES = {
    Heartbeat: st.builds(Heartbeat, version=st.integers(0, 255), role=st.sampled_from(Role),
                         uptime_ms=u32),
    ServoCommand: st.builds(ServoCommand, f32, f32),
    Telemetry: st.builds(Telemetry, board_time_ms=u32, roll=f32, pitch=f32, yaw=f32,
                         gyro=st.tuples(f32, f32, f32), accel=st.tuples(f32, f32, f32),
                         servo_1=f32, servo_2=f32, battery_v=f32, status=u16, gait_id=u16),
    ErrorReport: st.builds(ErrorReport, code=u8, ref_seq=u16),
    # Every value of a field without floats decodes: ranges are the receiver's rules.
    LinkConfig: st.builds(LinkConfig, u16, u8, u16, u16, u16),
    Ack: st.builds(Ack, u8, u16, u8),
    Gait: st.builds(Gait, u16, *[f32] * 10),
    TelemetryCompact: st.builds(TelemetryCompact, board_time_ms=u32, roll=i16, pitch=i16,
                                yaw=i16, gyro=st.tuples(i16, i16, i16),
                                accel=st.tuples(i16, i16, i16), servo_1=i16, servo_2=i16,
                                battery_mv=u16, status=u16, gait_id=u16),
    Health: st.builds(Health, u8, u8, u8, u32, u32, u32, u32, u32, u16, u16,
                      *[u32] * 7, u16, u16, u16),
    ServoTrim: st.builds(ServoTrim, servo=u8, op=u8, direction=i8, neutral_us=f32,
                         us_per_rad=f32, reserved=u8),
    ServoTrimReport: st.builds(ServoTrimReport, servo=u8, source=u8, direction=i8,
                               neutral_us=f32, us_per_rad=f32, min_us=f32, max_us=f32,
                               reserved=u8),
}
messages = st.one_of(*STRATEGIES.values())
TELEMETRY = Telemetry(board_time_ms=1234, roll=0.1, pitch=-0.2, yaw=3.0, gyro=(0.0, 0.5, -1.0),
                      accel=(0.25, 0.0, 9.75), servo_1=0.375, servo_2=-0.5, battery_v=8.125,
                      status=int(Status.LOW_BATTERY | Status.GAIT_MODE), gait_id=3)


def test_the_round_trips_cover_every_registered_message():
    assert set(STRATEGIES) == {message_class(kind) for kind in MsgType}


def test_frame_bounds_follow_the_largest_payload_health():
    # PROTOCOL.md: longest body 66, longest COBS run 67, longest frame on the wire 69.
    assert (MAX_BODY, MAX_ENCODED_FRAME) == (66, 67)
    assert len(encode_frame(Health(), 0)) == MAX_ENCODED_FRAME + 2


def test_crc16_is_ccitt_false():
    assert crc16(b'123456789') == 0x29B1


@given(messages, u16)
def test_round_trip_of_any_message(message, seq):
    frames = StreamDecoder().feed(encode_frame(message, seq))
    assert [(f.seq, f.message) for f in frames] == [(seq, message)]


@given(st.lists(messages, min_size=1, max_size=20), st.data())
@settings(max_examples=200)
def test_any_chunking_of_a_stream_yields_every_frame_in_order(batch, data):
    stream = b''.join(encode_frame(m, i) for i, m in enumerate(batch))
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=30)))
    decoder = StreamDecoder()
    frames = []
    for start, end in zip([0] + cuts, cuts + [len(stream)]):
        frames += decoder.feed(stream[start:end])
    assert [f.message for f in frames] == batch
    assert decoder.stats.resyncs == 0 and decoder.stats.seq_gaps == 0


@given(st.lists(st.binary(max_size=80), min_size=1, max_size=10), messages)
def test_frame_after_garbage_is_received(garbage_runs, message):
    decoder = StreamDecoder()
    decoder.feed(b''.join(garbage_runs))
    assert [f.message for f in decoder.feed(encode_frame(message, 7))] == [message]


@given(st.binary(max_size=5000))
def test_decoder_never_raises_and_memory_stays_bounded(data):
    decoder = StreamDecoder()
    decoder.feed(data)
    assert decoder.buffered <= MAX_ENCODED_FRAME


def test_telemetry_example_encodes_to_the_documented_hex():
    # The same frame is printed in PROTOCOL.md: keep the two in step.
    frame = encode_frame(TELEMETRY, 0x0102)
    assert frame.hex(' ') == (
        '00 06 20 02 01 d2 04 01 09 cd cc cc 3d cd cc 4c be 01 03 40 40 01 01 01 01 01 01 02 '
        '3f 01 03 80 bf 01 03 80 3e 01 01 01 01 01 03 1c 41 01 03 c0 3e 01 01 02 bf 01 06 02 '
        '41 08 01 03 03 ea d9 00')


def test_servo_command_example_encodes_to_the_documented_hex():
    frame = encode_frame(ServoCommand(0.25, -0.5), 0x0007)
    assert frame.hex(' ') == '00 03 10 07 01 01 03 80 3e 01 01 04 bf 9a dc 00'


def _corrupt(frame: bytes, index: int, xor: int) -> bytes:
    data = bytearray(frame)
    data[index] ^= xor
    return bytes(data)


def _reencoded(body: bytes) -> bytes:
    return b'\x00' + cobs.encode(body) + b'\x00'


GOOD = encode_frame(ServoCommand(0.1, 0.2), 1)
GOOD_BODY = encode_body(ServoCommand(0.1, 0.2), 1)


@pytest.mark.parametrize('stream, counter', [
    (_corrupt(GOOD, 6, 0x01), 'crc_errors'),                      # one flipped payload bit
    (_reencoded(GOOD_BODY[:-1] + bytes([GOOD_BODY[-1] ^ 0x80])), 'crc_errors'),
    (_reencoded(GOOD_BODY[:3]), 'short_frames'),
    (b'\x00\x05\x01\x02\x00', 'cobs_errors'),                    # code byte past the end
    (_reencoded(b'\x55\x01\x00' + struct.pack('<H', crc16(b'\x55\x01\x00'))), 'unknown_type'),
    (_reencoded(GOOD_BODY[:3] + b'\x00' * 4
                + struct.pack('<H', crc16(GOOD_BODY[:3] + b'\x00' * 4))), 'length_errors'),
    (_reencoded(GOOD_BODY[:3] + struct.pack('<ff', math.nan, 0.0)
                + struct.pack('<H', crc16(GOOD_BODY[:3] + struct.pack('<ff', math.nan, 0.0)))),
     'invalid_payload'),
    (b'\x01' * (MAX_ENCODED_FRAME + 1) + b'\x00', 'overflows'),
])
def test_each_kind_of_damage_is_rejected_and_counted_once(stream, counter):
    decoder = StreamDecoder()
    assert decoder.feed(stream) == []
    expected = DecoderStats(bytes_in=len(stream), resyncs=1).as_dict()
    expected[counter] = 1
    assert decoder.stats.as_dict() == expected


def test_overflow_is_skipped_up_to_the_next_delimiter_only():
    decoder = StreamDecoder()
    frames = decoder.feed(b'\x07' * 1000 + GOOD)
    assert [f.message for f in frames] == [StreamDecoder().feed(GOOD)[0].message]
    assert decoder.stats.overflows == 1 and decoder.stats.resyncs == 1


def test_missing_sequence_numbers_count_as_gaps():
    encoder = FrameEncoder()
    frames = [encoder.encode(ServoCommand(0.0, 0.0)) for _ in range(10)]
    decoder = StreamDecoder()
    decoder.feed(b''.join(frames[i] for i in (0, 1, 4, 5, 9)))
    assert decoder.stats.seq_gaps == 5


def test_sequence_numbers_wrap_without_gaps():
    encoder = FrameEncoder(first_seq=0xFFFE)
    decoder = StreamDecoder()
    decoder.feed(b''.join(encoder.encode(Heartbeat()) for _ in range(4)))
    assert (decoder.stats.frames_ok, decoder.stats.seq_gaps) == (4, 0)


def test_a_gait_with_a_non_finite_float_is_dropped_as_invalid():
    body = encode_body(Gait(1, 1.0, 0.1, 0.1), 5)
    payload = bytearray(body[3:-2])
    payload[2 + 4 * 9:2 + 4 * 10] = struct.pack('<f', math.inf)  # alpha
    stream = _reencoded(body[:3] + payload + struct.pack('<H', crc16(body[:3] + payload)))
    decoder = StreamDecoder()
    assert decoder.feed(stream) == [] and decoder.stats.invalid_payload == 1


def test_out_of_range_link_config_gait_and_health_values_still_decode():
    # The fish answers those with ACK 6; the host shows an unknown reset cause as a number.
    for message in (LinkConfig(5, 7, 1, 0, 65535), Gait(0, 50.0, -1.0, 9.0),
                    Health(reset_cause=200, clock_source=9), Ack(0x55, 3, 200)):
        (frame,) = StreamDecoder().feed(encode_frame(message, 1))
        assert frame.message == message
    (frame,) = StreamDecoder().feed(encode_frame(Health(ResetCause.IWDG, ClockSource.HSI), 1))
    assert frame.message.reset_cause is ResetCause.IWDG
    assert frame.message.clock_source is ClockSource.HSI


def test_error_report_carries_its_code():
    frame = encode_frame(ErrorReport(ErrorCode.BAD_CRC, 42), 3)
    (decoded,) = StreamDecoder().feed(frame)
    assert decoded.kind is MsgType.ERROR and decoded.message == ErrorReport(1, 42)
