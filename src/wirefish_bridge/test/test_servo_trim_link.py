# SPDX-License-Identifier: Apache-2.0
"""servo_trim_link: requests judged before they go out, the exchange, the sweep's ramps."""

import math

import pytest
from wirefish_bridge.protocol import (Ack, CalibrationSource, ErrorCode, MsgType, ServoTrim,
                                      ServoTrimReport, TrimOp)
from wirefish_bridge.servo_trim_link import (CalibrationState, Outcome, reason, ServoSweep,
                                             sweep_problem, trim_request, TrimExchange)

SET = ServoTrim(1, TrimOp.SET, 1, 1550.0, 600.0)
REPORT = ServoTrimReport(1, CalibrationSource.LIVE, 1, 1550.0, 600.0, 500.0, 2500.0)


@pytest.mark.parametrize('args, words', [
    ((1, 1, 1, math.nan, 600.0), 'neutral_us nan is not finite'),
    ((1, 2, 1, 1500.0, math.inf), 'us_per_rad inf is not finite'),
    ((3, 0, 0, 0.0, 0.0), 'servo 3 is neither 1 nor 2'),
    ((1, 1, 0, 1500.0, 600.0), 'direction 0 is neither +1 nor -1'),
    ((1, 1, 1, 1500.0, -5.0), 'us_per_rad -5 is not > 0'),
    ((1, 7, 1, 1500.0, 600.0), 'op 7 is not one of'),
])
def test_a_bad_request_is_refused_with_its_reason_and_no_frame(args, words):
    frame, why = trim_request(*args)
    assert frame is None and words in why


def test_read_and_factory_carry_no_values_whatever_was_asked():
    assert trim_request(2, TrimOp.FACTORY, 5, math.nan, 1.0) == (ServoTrim(2, TrimOp.FACTORY),
                                                                 '')
    assert trim_request(1, TrimOp.READ, 0, 0.0, 0.0) == (ServoTrim(1, TrimOp.READ), '')


def test_a_set_is_sent_as_asked():
    assert trim_request(1, TrimOp.SET, 1, 1550.0, 600.0) == (SET, '')


def test_the_exchange_resends_until_the_ack_and_report_come():
    exchange = TrimExchange(SET, 0.0, resend_s=0.4, timeout_s=2.0)
    assert exchange.due(0.0)
    exchange.sent(10, 0.0)
    assert not exchange.due(0.3) and exchange.due(0.4)
    exchange.sent(11, 0.4)
    assert exchange.on_ack(Ack(MsgType.SERVO_TRIM, 10, 0))
    assert not exchange.done
    assert exchange.on_report(REPORT)
    assert exchange.outcome is Outcome.ACCEPTED and exchange.reason() == ''


def test_a_report_before_an_accepting_ack_is_not_the_answer():
    exchange = TrimExchange(SET, 0.0, 0.4, 2.0)
    exchange.sent(3, 0.0)
    assert not exchange.on_report(REPORT)   # a boot report of a restarted fish, say
    assert not exchange.done


def test_an_ack_of_another_frame_or_type_is_not_the_answer():
    exchange = TrimExchange(SET, 0.0, 0.4, 2.0)
    exchange.sent(3, 0.0)
    assert not exchange.on_ack(Ack(MsgType.SERVO_TRIM, 4, 0))
    assert not exchange.on_ack(Ack(MsgType.GAIT, 3, 0))


def test_not_now_tells_how_to_switch_to_stream_mode():
    exchange = TrimExchange(SET, 0.0, 0.4, 2.0)
    exchange.sent(3, 0.0)
    exchange.on_ack(Ack(MsgType.SERVO_TRIM, 3, ErrorCode.NOT_NOW))
    assert exchange.outcome is Outcome.REFUSED
    words = exchange.reason('/x/bridge_node')
    assert 'gait mode' in words and 'ros2 param set /x/bridge_node drive_mode stream' in words


def test_a_request_that_could_not_be_sent_says_the_link_is_down():
    exchange = TrimExchange(SET, 0.0, 0.4, 2.0)
    assert not exchange.due(2.0)
    assert 'link to the fish is down' in exchange.reason()


def test_no_answer_within_the_timeout_says_so():
    exchange = TrimExchange(SET, 0.0, 0.4, 2.0)
    exchange.sent(3, 0.0)
    assert not exchange.due(2.0)
    assert exchange.outcome is Outcome.NO_ANSWER and 'no answer' in exchange.reason()


@pytest.mark.parametrize('code, words', [(6, 'out of range'), (8, 'storage failed'),
                                         (3, 'error 3 (UNKNOWN_TYPE)'), (99, 'error 99')])
def test_each_refusal_code_has_words(code, words):
    assert words in reason(code)


def test_the_state_keeps_each_servo_s_last_report():
    state = CalibrationState()
    assert state.reports == {1: None, 2: None}
    assert state.on_report(REPORT) and state.reports[1] == REPORT
    assert not state.on_report(ServoTrimReport(3, 0, 1, 1500.0, 600.0, 500.0, 2500.0))


def test_the_sweep_goes_0_up_down_and_back_to_0_with_the_other_servo_still():
    sweep = ServoSweep(2, 0.4, 4.0, 10.0)
    angles = [sweep.command(10.0 + t) for t in (0.0, 1.0, 2.0, 3.0, 3.5, 4.0)]
    assert [a[1] for a in angles] == pytest.approx([0.0, 0.4, 0.0, -0.4, -0.2, 0.0])
    assert all(a[0] == 0.0 for a in angles)
    assert not sweep.over(13.99) and sweep.over(14.0)


def test_the_sweep_never_moves_faster_than_its_ramps():
    sweep = ServoSweep(1, 0.3, 2.0, 0.0)
    angles = [sweep.angle(k * 0.001) for k in range(2001)]
    steps = [abs(b - a) for a, b in zip(angles, angles[1:])]
    assert max(steps) <= 4 * 0.3 / 2.0 * 0.001 + 1e-12


@pytest.mark.parametrize('args, words', [
    ((3, 0.3, 4.0), 'servo 3'), ((1, 2.0, 4.0), 'amplitude 2'),
    ((1, math.nan, 4.0), 'amplitude nan'), ((1, 0.3, 0.5), 'period 0.5'),
])
def test_a_bad_sweep_is_refused_with_its_reason(args, words):
    assert words in sweep_problem(*args, limit_rad=math.pi / 2)
