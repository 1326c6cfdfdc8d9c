# SPDX-License-Identifier: Apache-2.0
"""Protocol version 2: PROTOCOL.md's example frames, the fish's ranges, the compact telemetry."""

import dataclasses
import math
from pathlib import Path
import re

from hypothesis import given, strategies as st
import numpy as np
import pytest
from wirefish_bridge.codec import encode_frame, StreamDecoder
from wirefish_bridge.protocol import (Ack, ANGLE_LSB_RAD, CalibrationSource, ClockSource,
                                      ErrorCode, ErrorReport, Gait, Health, HealthFlags,
                                      Heartbeat, LinkConfig, MsgType, PROTOCOL_VERSION, quantize,
                                      ResetCause, Role, ServoCommand, ServoTrim, ServoTrimReport,
                                      Status, Telemetry, telemetry_of, TelemetryCompact,
                                      TelemetryForm, TrimOp)

PROTOCOL = Path(__file__).resolve().parents[1] / 'PROTOCOL.md'
TELEMETRY = Telemetry(board_time_ms=1234, roll=0.1, pitch=-0.2, yaw=3.0, gyro=(0.0, 0.5, -1.0),
                      accel=(0.25, 0.0, 9.75), servo_1=0.375, servo_2=-0.5, battery_v=8.125,
                      status=int(Status.LOW_BATTERY | Status.GAIT_MODE), gait_id=3)
# Every example of PROTOCOL.md's "Example frames", in the order it prints them: (message, seq).
EXAMPLES = [
    (Heartbeat(2, Role.HOST, 5000), 0),
    (Heartbeat(2, Role.FISH, 1500), 9),
    (LinkConfig(50, TelemetryForm.COMPACT, 5000, 1500, 3000), 4),
    (ServoCommand(0.25, -0.5), 7),
    (Gait(3, 1.5, 0.375, 0.5, 0.0625, -0.0625, -0.41, 0.64, 1.76, 1.06, 20.0), 8),
    (Ack(MsgType.GAIT, 8, 0), 12),
    (TELEMETRY, 0x0102),
    (TelemetryCompact(1234, 1000, -2000, 30000, (0, 500, -1000), (250, 0, 9750), 3750, -5000,
                      8125, int(Status.LOW_BATTERY | Status.GAIT_MODE), 3), 0x0103),
    (Health(ResetCause.FAULT, ClockSource.HSE_PLL, int(HealthFlags(15)), 0x08001234,
            0xFFFFFFF9, 0x00000400, 0x40000000, 123456, 612, 2048, 0, 0, 3, 1, 0, 0, 2, 1, 1,
            1), 0x0104),
    (ErrorReport(ErrorCode.BAD_CRC, 42), 3),
    (ServoTrim(1, TrimOp.SAVE, -1, 1520.0, 600.0), 13),
    (ServoTrimReport(1, CalibrationSource.STORED, -1, 1520.0, 600.0, 500.0, 2500.0), 14),
]


def documented_frames() -> list[bytes]:
    """Return the hex blocks of PROTOCOL.md's "Example frames" section, in order."""
    section = PROTOCOL.read_text().split('## Example frames', 1)[1].split('\n## ', 1)[0]
    return [bytes.fromhex(block.replace('\n', ' '))
            for block in re.findall(r'```\n(.*?)```', section, re.S)]


def test_protocol_md_is_version_2_with_an_example_of_every_type():
    assert PROTOCOL_VERSION == 2
    assert PROTOCOL.read_text().startswith('# wirefish serial protocol, version 2')
    assert len(documented_frames()) == len(EXAMPLES)
    assert {type(m).KIND for m, _ in EXAMPLES} == set(MsgType)


@pytest.mark.parametrize('index', range(len(EXAMPLES)),
                         ids=[type(m).__name__ + str(i) for i, (m, _) in enumerate(EXAMPLES)])
def test_each_example_frame_is_its_message_byte_for_byte(index):
    message, seq = EXAMPLES[index]
    wire = documented_frames()[index]
    assert encode_frame(message, seq) == wire
    (frame,) = StreamDecoder().feed(wire)
    assert (frame.kind, frame.seq) == (type(message).KIND, seq)
    assert encode_frame(frame.message, seq) == wire  # the values, as binary32


def test_the_compact_example_is_the_full_one_compacted():
    assert TelemetryCompact.from_telemetry(TELEMETRY) == EXAMPLES[7][0]


LIMIT = math.pi / 2
GOOD_GAIT = Gait(1, 1.0, 0.38, 0.47, 0.0, 0.0, -0.41, 0.64, 1.76, 1.06, 20.0)


def test_a_table_1_gait_is_valid():
    assert GOOD_GAIT.problem(LIMIT) is None
    edge = dataclasses.replace(GOOD_GAIT, gait_id=65535, frequency_hz=10.0, amplitude_1=0.0,
                               amplitude_2=LIMIT, offset_1=-LIMIT, offset_2=LIMIT, alpha=200.0,
                               w12=100.0, w21=-100.0, phi12=2 * math.pi, phi21=-2 * math.pi)
    assert edge.problem(LIMIT) is None
    # The largest binary32 bias a GAIT can carry within 2 pi (the board's bound) is valid; the
    # binary32 nearest 2 pi is just above it and refused, on both sides alike.
    below = float(np.nextafter(np.float32(2 * math.pi), np.float32(0)))
    assert dataclasses.replace(GOOD_GAIT, phi12=below).problem(LIMIT) is None
    above = float(np.float32(2 * math.pi))
    assert 'phi21' in dataclasses.replace(GOOD_GAIT, phi21=-above).problem(LIMIT)


@pytest.mark.parametrize('change, word', [
    ({'gait_id': 0}, 'gait_id'), ({'frequency_hz': 0.0}, 'frequency'),
    ({'frequency_hz': 10.01}, 'frequency'), ({'amplitude_1': -0.01}, 'amplitude_1'),
    ({'amplitude_2': 1.6}, 'amplitude_2'), ({'offset_1': -1.6}, 'offset_1'),
    ({'alpha': 0.0}, 'alpha'), ({'alpha': 201.0}, 'alpha'), ({'w12': math.nan}, 'finite'),
    ({'w12': 100.001}, 'w12'), ({'w21': -1e30}, 'w21'), ({'phi12': 6.3}, 'phi12'),
    ({'phi21': -7.0}, 'phi21'),
])
def test_each_gait_out_of_range_is_named(change, word):
    problem = dataclasses.replace(GOOD_GAIT, **change).problem(LIMIT)
    assert problem is not None and word in problem


def test_link_config_ranges():
    assert LinkConfig().problem() is None
    assert LinkConfig(10, 1, 0, 100, 0).problem() is None
    assert LinkConfig(1000, 0, 60000, 10000, 60000).problem() is None
    for bad, word in ((LinkConfig(telemetry_period_ms=9), 'telemetry_period_ms'),
                      (LinkConfig(telemetry_period_ms=1001), 'telemetry_period_ms'),
                      (LinkConfig(telemetry_form=2), 'telemetry_form'),
                      (LinkConfig(health_period_ms=199), 'health_period_ms'),
                      (LinkConfig(health_period_ms=60001), 'health_period_ms'),
                      (LinkConfig(link_timeout_ms=99), 'link_timeout_ms'),
                      (LinkConfig(coast_ms=60001), 'coast_ms')):
        problem = bad.problem()
        assert problem is not None and word in problem


def test_quantize_rounds_halves_away_from_zero_and_saturates():
    assert [quantize(v, 1.0) for v in (0.5, -0.5, 1.5, -1.5, 0.49, -2.51)] == [
        1, -1, 2, -2, 0, -3]
    assert quantize(4.0, 1e-4) == 32767 and quantize(-4.0, 1e-4) == -32768
    assert quantize(math.inf, 1e-3) == 32767 and quantize(-math.inf, 1e-3) == -32768
    assert quantize(math.nan, 1e-3) == 0
    assert quantize(-1.0, 1e-3, (0, 0xFFFF)) == 0 and quantize(70.0, 1e-3, (0, 0xFFFF)) == 65535


angles = st.floats(-math.pi, math.pi)


@given(angles, st.floats(-math.pi / 2, math.pi / 2), angles, angles, angles,
       st.tuples(*[st.floats(-30.0, 30.0)] * 3), st.tuples(*[st.floats(-30.0, 30.0)] * 3),
       st.floats(0.0, 9.0), st.integers(0, 0x3FF), st.integers(0, 0xFFFF))
def test_compact_telemetry_expands_to_the_full_one_within_half_a_count(
        roll, pitch, yaw, servo_1, servo_2, gyro, accel, battery_v, status, gait_id):
    full = Telemetry(77, roll, pitch, yaw, gyro, accel, servo_1, servo_2, battery_v, status,
                     gait_id)
    compact = TelemetryCompact.from_telemetry(full)
    (frame,) = StreamDecoder().feed(encode_frame(compact, 1))
    back = telemetry_of(frame.message)
    assert (back.board_time_ms, back.status, back.gait_id) == (77, status, gait_id)
    got = np.array([back.roll, back.pitch, back.yaw, back.servo_1, back.servo_2])
    want = np.array([roll, pitch, yaw, servo_1, servo_2])
    assert np.all(np.abs(got - want) <= ANGLE_LSB_RAD / 2 + 1e-12)
    assert np.all(np.abs(np.subtract(back.gyro, gyro)) <= 0.5e-3 + 1e-12)
    assert np.all(np.abs(np.subtract(back.accel, accel)) <= 0.5e-3 + 1e-12)
    assert abs(back.battery_v - battery_v) <= 0.5e-3 + 1e-12


def test_telemetry_of_gives_the_full_form_of_either_and_nothing_of_the_others():
    assert telemetry_of(TELEMETRY) is TELEMETRY
    assert telemetry_of(EXAMPLES[7][0]) == dataclasses.replace(
        TELEMETRY, roll=1000 * ANGLE_LSB_RAD, pitch=-2000 * ANGLE_LSB_RAD,
        yaw=30000 * ANGLE_LSB_RAD, gyro=(0.0, 0.5, -1.0), accel=(0.25, 0.0, 9.75),
        servo_1=3750 * ANGLE_LSB_RAD, servo_2=-5000 * ANGLE_LSB_RAD)
    assert telemetry_of(Heartbeat()) is None and telemetry_of(Health()) is None
