# SPDX-License-Identifier: Apache-2.0
"""Gait mode's pure parts: GAIT and LINK_CONFIG until acknowledged, the oscillator watch."""

import math

import pytest
from wirefish_bridge.gait_link import (ConfigLink, GaitLink, GaitParameters, next_gait_id,
                                       OscillatorWatch, percentile)
from wirefish_bridge.protocol import Ack, ErrorCode, LinkConfig, MsgType, TelemetryForm

STRAIGHT = GaitParameters(1.0, (0.3, 0.4), (0.0, 0.0), 4.0, 4.0, -0.5, 0.5, 20.0)
TURN = GaitParameters(1.0, (0.3, 0.4), (0.1, 0.1), 4.0, 4.0, -0.5, 0.5, 20.0)


def test_a_new_gait_is_due_at_once_with_the_next_id():
    link = GaitLink(resend_s=0.5)
    assert link.due(0.0) is None
    assert link.set_gait(STRAIGHT, 0.0)
    gait = link.due(0.0)
    assert gait is not None and gait.gait_id == 1 and gait.amplitude_2 == 0.4
    assert gait.problem(math.pi / 2) is None
    assert not link.set_gait(STRAIGHT, 0.1)   # the same parameters: no new gait
    assert link.set_gait(TURN, 0.2) and link.due(0.2).gait_id == 2


def test_an_unacknowledged_gait_goes_again_every_resend_period():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(10, 0.0)
    assert link.due(0.4) is None
    assert link.due(0.5) is not None
    link.sent(14, 0.5)
    link.on_ack(Ack(MsgType.GAIT, 10), 0.7)   # the first send's ACK, late: it counts
    assert link.acknowledged and link.due(5.0) is None
    assert list(link.ack_latencies_s) == [pytest.approx(0.7)]


def test_an_ack_of_another_frame_acknowledges_nothing():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(3, 0.0)
    link.on_ack(Ack(MsgType.GAIT, 4), 0.1)
    link.on_ack(Ack(MsgType.LINK_CONFIG, 3), 0.1)
    assert not link.acknowledged


def test_telemetry_with_the_gait_id_acknowledges_it():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.on_telemetry(1, 0.05)    # not sent yet: an old board state, not an answer
    assert not link.acknowledged
    link.sent(0, 0.1)
    link.on_telemetry(1, 0.3)
    assert link.acknowledged
    assert list(link.ack_latencies_s) == [pytest.approx(0.3)]


def test_a_refusal_stops_the_resends_until_the_next_change():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(0, 0.0)
    link.on_ack(Ack(MsgType.GAIT, 0, ErrorCode.COMMAND_OUT_OF_RANGE), 0.1)
    assert link.refusal == ErrorCode.COMMAND_OUT_OF_RANGE and link.due(2.0) is None
    assert link.values()['gait_refused'] == 'error 6'
    link.set_gait(TURN, 3.0)
    assert link.refusal is None and link.due(3.0) is not None


def test_a_board_that_forgot_the_gait_gets_it_again():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(0, 0.0)
    link.on_telemetry(1, 0.1)
    assert link.due(0.2) is None
    link.on_telemetry(0, 5.0)     # reset, or back in stream mode
    assert link.due(5.0) is not None and link.due(5.0).gait_id == 1
    link.sent(1, 5.0)
    link.on_fish_restart()
    assert link.due(5.01) is not None


def test_a_newer_gait_acknowledged_covers_the_older_ones():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(1, 0.0)
    link.set_gait(TURN, 0.1)          # supersedes gait 1 before its ACK
    link.sent(2, 0.1)
    link.on_ack(Ack(MsgType.GAIT, 2), 0.3)
    assert link.acknowledged
    assert sorted(link.ack_latencies_s) == [pytest.approx(0.2), pytest.approx(0.3)]
    link.on_ack(Ack(MsgType.GAIT, 1), 0.35)   # late: nothing left to acknowledge
    assert len(link.ack_latencies_s) == 2


def test_new_gaits_keep_the_minimum_interval():
    link = GaitLink(resend_s=0.5, min_interval_s=0.1)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(1, 0.0)
    link.set_gait(TURN, 0.05)
    assert link.due(0.05) is None and link.due(0.1).gait_id == 2


def test_the_wait_of_the_oldest_unacknowledged_gait_is_kept():
    link = GaitLink(resend_s=0.5)
    assert link.waiting_s(1.0) == 0.0
    link.set_gait(STRAIGHT, 1.0)
    link.sent(1, 1.0)
    link.set_gait(TURN, 1.5)
    assert link.waiting_s(2.0) == pytest.approx(1.0)
    link.on_telemetry(2, 2.1)
    link.sent(2, 1.6)
    link.on_telemetry(2, 2.2)
    assert link.waiting_s(3.0) == 0.0


def test_gait_ids_skip_zero():
    assert next_gait_id(0) == 1
    assert next_gait_id(65534) == 65535
    assert next_gait_id(65535) == 1


def test_link_config_waits_for_the_link_and_is_sent_until_accepted():
    config = LinkConfig(100, TelemetryForm.COMPACT, 2000, 1500, 3000)
    link = ConfigLink(config, resend_s=0.5)
    assert link.due(0.0) is None           # no fish yet
    link.link_up(1.0)
    assert link.due(1.0) == config
    link.sent(7, 1.0)
    assert link.due(1.2) is None and link.due(1.5) == config
    link.sent(8, 1.5)
    link.on_ack(Ack(MsgType.LINK_CONFIG, 8))
    assert link.acknowledged and link.due(9.0) is None
    link.link_up(10.0)                     # the link came back: the fish may have restarted
    assert link.due(10.0) == config


def test_a_refused_link_config_is_not_sent_again():
    link = ConfigLink(LinkConfig(5), resend_s=0.5)
    link.link_up(0.0)
    link.sent(1, 0.0)
    link.on_ack(Ack(MsgType.LINK_CONFIG, 1, ErrorCode.COMMAND_OUT_OF_RANGE))
    assert link.refusal == ErrorCode.COMMAND_OUT_OF_RANGE and link.due(9.0) is None


def _feed(watch: OscillatorWatch, seconds: float, host: tuple[float, float, float],
          board: tuple[float, float, float], board_rate_hz: float = 10.0) -> float:
    """Feed (amplitude, offset, phase) sines at 100 Hz (host) and ``board_rate_hz``; end time."""
    t = 0.0
    k = 0
    while t < seconds:
        watch.add_host(t, tuple(host[1] + host[0] * math.sin(2 * math.pi * t + host[2])
                                for _ in range(2)))
        if k % round(100 / board_rate_hz) == 0:
            watch.add_board(t, tuple(board[1] + board[0] * math.sin(2 * math.pi * t + board[2])
                                     for _ in range(2)))
        k += 1
        t = k / 100.0
    return t


def test_the_same_oscillation_in_another_phase_does_not_diverge():
    watch = OscillatorWatch(window_s=2.0, bound_rad=0.1)
    now = _feed(watch, 5.0, (0.4, 0.1, 0.0), (0.4, 0.1, 2.0))
    assert watch.divergence(now) < 0.03
    assert watch.problem(now) is None


def test_another_amplitude_or_offset_diverges():
    watch = OscillatorWatch(window_s=2.0, bound_rad=0.1)
    now = _feed(watch, 5.0, (0.4, 0.1, 0.0), (0.1, 0.0, 0.0))
    # |0.1 - 0| + (0.4 - 0.1) / sqrt(2) = 0.31 rad
    assert watch.divergence(now) == pytest.approx(0.1 + 0.3 / math.sqrt(2), abs=0.03)
    assert 'diverges' in watch.problem(now)


def test_no_divergence_is_judged_without_both_streams():
    watch = OscillatorWatch(window_s=2.0, bound_rad=0.1)
    assert watch.divergence(0.0) is None
    _feed(watch, 5.0, (0.4, 0.1, 0.0), (0.0, 0.0, 0.0))
    assert watch.divergence(9.0) is None   # both stopped 4 s ago


def test_percentile_is_the_nearest_rank():
    assert percentile([1.0, 2.0, 3.0, 4.0], 0.5) == 2.0
    assert percentile([1.0, 2.0, 3.0, 4.0], 0.99) == 4.0
    assert math.isnan(percentile([], 0.5))


def test_a_new_gait_goes_twice_then_every_resend_period():
    link = GaitLink(resend_s=0.5, repeat_s=0.15)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(1, 0.0)
    assert link.due(0.14) is None and link.due(0.15).gait_id == 1
    link.sent(2, 0.15)
    assert link.due(0.6) is None and link.due(0.65).gait_id == 1


def test_the_ack_of_either_copy_acknowledges_the_gait_and_stops_the_copies():
    link = GaitLink(resend_s=0.5, repeat_s=0.15)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(1, 0.0)
    link.sent(2, 0.15)
    link.on_ack(Ack(MsgType.GAIT, 2), 0.3)   # the first copy was lost
    assert link.acknowledged and link.due(1.0) is None
    assert list(link.ack_latencies_s) == [pytest.approx(0.3)]


def test_an_acknowledged_first_copy_sends_no_second():
    link = GaitLink(resend_s=0.5, repeat_s=0.15)
    link.set_gait(STRAIGHT, 0.0)
    link.sent(1, 0.0)
    link.on_ack(Ack(MsgType.GAIT, 1), 0.1)
    assert link.due(0.15) is None


def test_a_gait_taken_before_the_link_was_configured_waits_from_then():
    link = GaitLink(resend_s=0.5)
    link.set_gait(STRAIGHT, 1.0)
    link.waits_from(3.0)
    link.sent(1, 3.0)
    link.on_ack(Ack(MsgType.GAIT, 1), 3.2)
    assert list(link.ack_latencies_s) == [pytest.approx(0.2)]
