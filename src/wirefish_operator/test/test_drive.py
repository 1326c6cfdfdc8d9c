# SPDX-License-Identifier: Apache-2.0
"""`wirefish drive`: keys to cmd_vel, and the status line."""

import math
from types import SimpleNamespace

import pytest
from wirefish_operator.verb.drive import DriveLimits, key_action, KeyDecoder, state_line

LIMITS = DriveLimits(speed_step=0.05, max_speed=0.1, turn_step=0.1, max_turn=0.2)


@pytest.mark.parametrize('key, expected', [
    ('w', (0.1, 0.0)), ('\x1b[A', (0.1, 0.0)), ('s', (0.0, 0.0)), ('\x1b[B', (0.0, 0.0)),
    ('a', (0.05, 0.1)), ('\x1b[D', (0.05, 0.1)), ('d', (0.05, -0.1)), ('\x1b[C', (0.05, -0.1)),
    ('\x1bOA', (0.1, 0.0)), ('\x1bOD', (0.05, 0.1)), (' ', (0.0, 0.0)), ('x', (0.05, 0.0)),
])
def test_keys_change_speed_and_turn(key, expected):
    assert key_action(key, 0.05, 0.0, LIMITS) == pytest.approx(expected)


def test_speed_and_turn_stay_within_their_limits():
    assert key_action('w', 0.1, 0.0, LIMITS) == (0.1, 0.0)
    assert key_action('s', 0.0, 0.0, LIMITS) == (0.0, 0.0)  # never backwards
    assert key_action('d', 0.0, -0.2, LIMITS) == (0.0, -0.2)


@pytest.mark.parametrize('key', ['q', 'Q', '\x03'])
def test_quit(key):
    assert key_action(key, 0.1, 0.1, LIMITS) is None


def test_an_arrow_sequence_is_one_key():
    assert KeyDecoder().feed(b'w\x1b[Aa ') == ['w', '\x1b[A', 'a', ' ']


# Arrow keys, each cut between two reads at every place it can be cut.
SPLITS = [(b'\x1b', b'[A'), (b'\x1b[', b'A'), (b'w\x1b', b'[D'), (b'\x1bO', b'C'),
          (b'\x1b[1;', b'5B')]


@pytest.mark.parametrize('first, second', SPLITS)
def test_a_sequence_cut_between_reads_is_one_key_when_whole(first, second):
    decoder = KeyDecoder()
    before = decoder.feed(first)
    assert [k for k in before if k.startswith('\x1b')] == []
    assert before + decoder.feed(second) == [*(['w'] if first.startswith(b'w') else []),
                                             (first + second).decode().lstrip('w')]


def test_a_lone_escape_does_not_swallow_the_next_key():
    assert KeyDecoder().feed(b'\x1bw') == ['\x1b', 'w']


def test_a_multibyte_character_cut_between_reads_is_one_key():
    decoder = KeyDecoder()
    assert decoder.feed('é'.encode()[:1]) == [] and decoder.feed('é'.encode()[1:]) == ['é']


def test_status_line_shows_the_planner_state_and_why_it_clamps():
    state = SimpleNamespace(mode='hold', predicted_speed=0.39, tail_beat_hz=4.0,
                            amplitude_scale=0.73, yaw_rate_target=0.0,
                            yaw_rate_measured=0.01, offset=0.02, heading_target=0.5,
                            clamp_reason='0.500 m/s is above the fastest feasible gait',
                            note='')
    line = state_line(0.5, 0.0, state)
    assert 'hold' in line and '0.39 m/s' in line and 'above the fastest' in line
    assert f'{math.degrees(0.5):+.0f} deg' in line
    assert 'no planner_state' in state_line(0.0, 0.0, None)


def test_without_planner_state_the_line_names_the_graph_it_waits_for():
    assert 'no planner_state yet' in state_line(0.0, 0.0, None, waited_s=1.0, namespace='/f')
    line = state_line(0.0, 0.0, None, waited_s=3.5, namespace='/f')
    assert 'no planner_state in /f after 4 s' in line and 'wirefish up --namespace /f' in line
