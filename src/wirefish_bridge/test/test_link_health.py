# SPDX-License-Identifier: Apache-2.0
"""Link health: the diagnostic level's rules and the /diagnostics values, without ROS."""

from dataclasses import fields

import pytest
from wirefish_bridge.codec import DecoderStats
from wirefish_bridge.link_health import (DECODER_KEYS, identifies_fish, Level, LINK_KEYS,
                                         LinkHealth, RateMeter)
from wirefish_bridge.protocol import (ErrorReport, Heartbeat, Role, ServoCommand, Status,
                                      Telemetry, TelemetryCompact)
from wirefish_bridge.transport import LinkState, LinkStats

PORT = '/dev/fish'
TELEMETRY = Telemetry(board_time_ms=1, roll=0.0, pitch=0.0, yaw=0.0, gyro=(0.0, 0.0, 0.0),
                      accel=(0.0, 0.0, 9.8), servo_1=0.0, servo_2=0.0, battery_v=8.0)


@pytest.fixture
def health() -> LinkHealth:
    h = LinkHealth(heartbeat_timeout_s=1.0, now=0.0)
    h.on_heartbeat(Heartbeat(role=Role.FISH), now=10.0)
    return h


@pytest.mark.parametrize('message, fish', [
    (Heartbeat(role=Role.FISH), True), (Heartbeat(role=Role.HOST), False),
    (TELEMETRY, False), (ServoCommand(0.0, 0.0), False), (ErrorReport(1), False),
])
def test_only_a_fish_heartbeat_identifies_a_fish(message, fish):
    assert identifies_fish(message) is fish


@pytest.mark.parametrize('state, stats, now, failsafe, level, words', [
    (LinkState.IDENTIFYING, LinkStats(), 10.1, False, Level.ERROR, 'sent no fish heartbeat'),
    (LinkState.CONNECTING, LinkStats(last_error='in use by another process (pid 7)'), 10.1,
     False, Level.ERROR, 'in use by another process (pid 7)'),
    (LinkState.CONNECTING, LinkStats(last_open_unidentified=True), 10.1, False, Level.ERROR,
     'not a fish?'),
    (LinkState.CONNECTED, LinkStats(), 11.5, False, Level.WARN, 'heartbeat stale'),
    (LinkState.CONNECTED, LinkStats(), 10.1, True, Level.WARN, 'commanding neutral'),
    (LinkState.CONNECTED, LinkStats(), 10.1, False, Level.OK, 'connected'),
])
def test_the_level_names_the_first_problem(health, state, stats, now, failsafe, level, words):
    got, message = health.level(now, state, PORT, stats, failsafe)
    assert got is level and words in message


def test_a_fish_of_another_protocol_version_is_an_error(health):
    logged = health.on_heartbeat(Heartbeat(version=9, role=Role.FISH), now=10.2)
    assert logged[0] is Level.ERROR
    level, message = health.level(10.3, LinkState.CONNECTED, PORT, LinkStats(), False)
    assert level is Level.ERROR and 'version mismatch (9)' in message


def test_a_new_device_is_not_taken_for_the_old_fish(health):
    health.on_new_device()
    assert health.heartbeat_age(10.1) == float('inf') and health.fish_version is None


def test_every_decoder_and_link_counter_is_in_the_values(health):
    values = health.values(11.0, LinkState.CONNECTED, PORT, DecoderStats(), LinkStats(), {})
    for f in fields(DecoderStats):
        assert DECODER_KEYS.get(f.name, f.name) in values
    for f in fields(LinkStats):
        assert LINK_KEYS.get(f.name, f.name) in values or LINK_KEYS.get(f.name, 0) is None


def test_impossible_telemetry_is_counted_and_not_taken_as_heard(health):
    assert health.on_telemetry(TELEMETRY, now=10.0) is None
    problem = health.on_telemetry(Telemetry(**{**TELEMETRY.__dict__, 'roll': 3.4e38}), 10.5)
    assert 'roll' in problem
    values = health.values(11.0, LinkState.CONNECTED, PORT, DecoderStats(), LinkStats(), {})
    assert values['telemetry_rejected'] == 1 and values['last_telemetry_age_s'] == 1.0


def test_an_error_report_is_counted_with_its_name(health):
    assert 'BAD_CRC about frame 42' in health.on_error_report(ErrorReport(1, 42))
    assert 'code 200' in health.on_error_report(ErrorReport(200, 0))
    assert health.fish_errors == 2


def test_rate_meter_counts_per_second_between_readings():
    meter = RateMeter(now=0.0)
    assert meter.rate(2.0, 100) == 50.0
    assert meter.rate(3.0, 100) == 0.0


def test_compact_telemetry_is_judged_and_taken_as_the_full_form(health):
    coasting = TelemetryCompact.from_telemetry(Telemetry(
        1, 0.0, 0.0, 3.14159, (0.0, 0.0, 0.0), (0.0, 0.0, 9.8), 0.4, -0.4, 8.0,
        int(Status.GAIT_MODE | Status.COASTING), 7))
    assert health.on_telemetry(coasting, now=11.0) is None
    assert health.fish_status == Status.GAIT_MODE | Status.COASTING
    impossible = TelemetryCompact.from_telemetry(TELEMETRY)  # gait id 0 yet coasting
    assert 'gait mode' in health.on_telemetry(
        TelemetryCompact(**{**impossible.__dict__, 'status': int(Status.COASTING)}), now=12.0)
    assert health.telemetry_rejected == 1
