# SPDX-License-Identifier: Apache-2.0
"""`wirefish up`'s status view: the columns and the header it shows (pure: no ROS)."""

import io
from types import SimpleNamespace

import pytest
from wirefish_launcher.status_view import (battery_text, is_hidden, link_text, rate_text,
                                           RateWindow, TerminalBlock)


@pytest.mark.parametrize('topic, hidden', [
    ('/wirefish/retune_gait/_action/feedback', True), ('/wirefish/_private', True),
    ('/wirefish/servo_cmd', False), ('/diagnostics', False)])
def test_hidden_topics_are_those_with_a_token_starting_with_underscore(topic, hidden):
    assert is_hidden(topic) is hidden


@pytest.mark.parametrize('rate, latched, received, text', [
    (100.04, False, 300, '100.0 Hz'), (0.0, False, 0, 'no msgs'),
    (0.0, True, 1, 'latched'), (0.0, True, 0, 'no msgs'), (2.0, True, 8, '2.0 Hz, latched')])
def test_a_latched_topic_with_its_sample_reads_latched_not_no_msgs(
        rate, latched, received, text):
    assert rate_text(rate, latched, received) == text


def test_the_rate_is_over_the_last_window():
    window = RateWindow(window_s=2.0)
    window.add(10.0, 0)
    for step in range(1, 31):  # 10 messages every 0.1 s for 3 s: 100 Hz
        window.add(10.0 + 0.1 * step, 10)
    assert window.rate(13.0) == pytest.approx(100.0, rel=0.06)
    window.add(14.0, 0)
    assert window.rate(14.0) == pytest.approx(50.0, rel=0.11)  # half of the last 2 s was silent


def _status(name, level, message):
    return SimpleNamespace(name=name, level=bytes([level]), message=message)


def test_the_link_is_the_bridges_serial_link_status():
    statuses = [_status('/w/planner_node: planner', 0, 'ok'),
                _status('/w/bridge_node: serial link /tmp/tty', 2, 'no heartbeat for 2.0 s')]
    assert link_text(statuses) == 'ERROR: no heartbeat for 2.0 s'
    assert link_text([_status('/w/bridge_node: serial link /tmp/tty', 0, 'ok')]) == 'OK'
    assert link_text(statuses[:1]) == 'no serial link diagnostics yet'


def test_the_battery_shows_what_it_knows():
    assert battery_text(SimpleNamespace(voltage=7.923, percentage=0.85)) == '7.92 V, 85 %'
    assert battery_text(SimpleNamespace(voltage=8.2, percentage=float('nan'))) == '8.20 V'


def test_the_block_is_redrawn_in_place():
    stream = io.StringIO()
    block = TerminalBlock(stream)
    block.draw(['a', 'b', 'c'])
    block.draw(['d', 'e'])
    assert stream.getvalue() == '\x1b[Ja\nb\nc\n\x1b[3F\x1b[Jd\ne\n'
    block.forget()
    block.draw(['f'])
    assert stream.getvalue().endswith('d\ne\n\x1b[Jf\n')  # below what was left


def test_the_planners_mode_is_shown_as_what_the_tail_does():
    from wirefish_launcher.status_view import MODE_MEANINGS, planner_text
    from wirefish_planner.planner_core import PlannerMode

    assert planner_text(SimpleNamespace(mode='still')) == (
        'still: servos at neutral until the first command')
    assert planner_text(SimpleNamespace(mode='turn')) == 'turn'
    assert set(MODE_MEANINGS) <= {mode.value for mode in PlannerMode}
