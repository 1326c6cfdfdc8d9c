# SPDX-License-Identifier: Apache-2.0
"""The radio link model: air time, duplex, gathering, latency, burst loss, corruption, cuts."""

from dataclasses import replace
import random

import pytest
from wirefish_sim.radio_model import (Direction, frame_units, preset, PRESETS, RadioLink,
                                      RadioParameters)

TO_FISH, TO_HOST = Direction.TO_FISH, Direction.TO_HOST


Delivery = tuple[float, Direction, bytes]


def run(link: RadioLink, until: float, step: float = 0.0005) -> list[Delivery]:
    """Poll ``link`` every ``step`` s until ``until``; return (time, direction, bytes)."""
    got = []
    t = link.stats.started_s
    while t <= until:
        got += [(t, d, data) for d, data in link.poll(t)]
        t += step
    return got


def clean(params: RadioParameters) -> RadioParameters:
    """Return ``params`` without loss, corruption, jitter or UART: the channel alone."""
    return replace(params, loss_good=0.0, loss_bad=0.0, byte_error_good=0.0,
                   byte_error_bad=0.0, jitter_s=0.0, bad_mean_s=0.0, uart_baud=0.0)


def test_a_wired_frame_arrives_after_its_air_time_whole():
    link = RadioLink(PRESETS['wired'], random.Random(1), 0.0)
    frame = bytes(range(62))
    link.send(TO_HOST, frame, 0.0)
    got = run(link, 0.02, step=0.0001)
    air = 62 * 10 / 115200   # eq. R1: 5.38 ms
    assert [(d, data) for _, d, data in got] == [(TO_HOST, frame)]
    assert air <= got[0][0] < air + 0.0002


def test_full_duplex_carries_both_ways_at_once():
    link = RadioLink(PRESETS['wired'], random.Random(1), 0.0)
    link.send(TO_HOST, b'a' * 60, 0.0)
    link.send(TO_FISH, b'b' * 60, 0.0)
    got = run(link, 0.01, step=0.0001)
    times = {d: t for t, d, _ in got}
    assert abs(times[TO_HOST] - times[TO_FISH]) < 0.0002


def test_half_duplex_waits_for_the_channel_and_turns_around():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    link.send(TO_HOST, b'a' * 60, 0.0)    # a full packet: sent at once
    link.send(TO_FISH, b'b' * 20, 0.001)  # waits for the channel, then the turn-around
    got = run(link, 0.5)
    times = {d: t for t, d, _ in got}
    first = params.air_time_s(60)
    second = first + params.turnaround_s + params.air_time_s(20)
    assert times[TO_HOST] == pytest.approx(first + params.latency_s, abs=0.001)
    assert times[TO_FISH] == pytest.approx(max(second, 0.001 + params.gather_s
                                               + params.air_time_s(20))
                                           + params.latency_s, abs=0.001)
    assert link.stats.turnarounds == 1


def test_half_duplex_ends_take_turns_when_both_wait():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    link.send(TO_HOST, b'a' * 240, 0.0)   # four packets
    link.send(TO_FISH, b'b' * 120, 0.0)   # two packets
    got = run(link, 1.0)
    order = [d for _, d, _ in got]
    assert order[:4] == [TO_HOST, TO_FISH, TO_HOST, TO_FISH]


def test_bytes_written_close_together_go_in_one_packet():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    link.send(TO_FISH, b'ab', 0.0)
    link.send(TO_FISH, b'cd', 0.001)        # within gather_s of the last byte
    link.send(TO_FISH, b'ef', 0.2)          # long after: a packet of its own
    got = run(link, 0.5)
    assert [data for _, _, data in got] == [b'abcd', b'ef']
    assert link.stats.to_fish.packets_sent == 2


def test_a_full_buffer_loses_what_does_not_fit():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    link.send(TO_HOST, bytes(300), 0.0)
    assert link.stats.to_host.bytes_overflowed == 300 - params.buffer_bytes
    got = run(link, 2.0)
    assert sum(len(data) for _, _, data in got) == params.buffer_bytes


def test_jitter_never_reorders_a_direction():
    params = replace(clean(PRESETS['rf433']), jitter_s=0.05, gather_s=0.0,
                     half_duplex=False)
    link = RadioLink(params, random.Random(3), 0.0)
    got = []
    for k in range(200):
        link.send(TO_HOST, bytes([k]), k * 0.002)
        got += link.poll(k * 0.002)
    got += link.poll(2.0)
    assert b''.join(data for _, data in got) == bytes(range(200))
    assert len(got) > 20   # many packets, each with its own jitter


def test_burst_loss_matches_the_share_of_bad_time():
    # loss only in BAD: the lost share of many small packets is bad / (good + bad) (eq. R4).
    params = replace(clean(PRESETS['wired']), good_mean_s=1.0, bad_mean_s=0.25,
                     loss_bad=1.0)
    link = RadioLink(params, random.Random(7), 0.0)
    sent = 0
    t = 0.0
    while t < 2000.0:
        link.send(TO_HOST, b'x', t)
        link.poll(t)
        sent += 1
        t += 0.05
    lost = link.stats.to_host.packets_lost / sent
    assert lost == pytest.approx(0.25 / 1.25, abs=0.02)


def test_losses_come_in_bursts():
    params = replace(clean(PRESETS['wired']), good_mean_s=2.0, bad_mean_s=0.5, loss_bad=1.0)
    link = RadioLink(params, random.Random(11), 0.0)
    received = []
    for k in range(20000):
        t = k * 0.01
        link.send(TO_HOST, k.to_bytes(2, 'little'), t)
        received += [int.from_bytes(data, 'little') for _, data in link.poll(t)]
    gaps = [b - a - 1 for a, b in zip(received, received[1:]) if b - a > 1]
    # Independent losses of the same share would make gaps of ~1 packet; BAD stays of 0.5 s
    # lose ~50 in a row.
    assert sum(gaps) / len(gaps) > 20


def test_a_cut_loses_what_is_on_the_air_then_the_link_is_back():
    link = RadioLink(PRESETS['wired'], random.Random(1), 0.0)
    link.cut(1.0, 2.0)
    arrived = []
    for k in range(300):
        t = k * 0.01
        link.send(TO_FISH, bytes([k % 256]), t)
        arrived += [t for _, _ in link.poll(t)]
    assert not [t for t in arrived if 1.001 < t < 2.0]
    assert any(2.0 <= t < 2.02 for t in arrived)
    assert link.stats.to_fish.packets_cut == pytest.approx(100, abs=1)


def test_corruption_changes_bytes_at_its_rate():
    params = replace(clean(PRESETS['wired']), byte_error_good=0.01)
    link = RadioLink(params, random.Random(5), 0.0)
    for k in range(1000):
        link.send(TO_HOST, bytes(100), k * 0.01)
    got = run(link, 11.0, step=0.01)
    changed = sum(sum(1 for b in data if b) for _, _, data in got)
    assert changed == link.stats.to_host.bytes_corrupted
    assert changed / 100000 == pytest.approx(0.01, rel=0.1)


def test_the_same_seed_gives_the_same_link():
    def once() -> list:
        link = RadioLink(PRESETS['rf433'], random.Random(42), 0.0)
        out = []
        for k in range(2000):
            t = k * 0.005
            link.send(Direction(k % 2), bytes([k % 256]) * 10, t)
            out += link.poll(t)
        return out
    assert once() == once()


def test_link_use_is_air_time_over_elapsed_time():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    # 60-byte writes at 5 Hz: 5 * (9 + 60) * 8 / 15000 = 0.184 of the air.
    for k in range(50):
        link.send(TO_HOST, bytes(60), k * 0.2)
        link.poll(k * 0.2)
    assert link.stats.use(TO_HOST, 10.0) == pytest.approx(5 * params.air_time_s(60), rel=0.01)
    assert link.stats.use(TO_FISH, 10.0) == 0.0
    assert link.stats.load(TO_HOST, 10.0, 1000.0) == pytest.approx(0.3)


def test_next_event_says_when_to_poll():
    params = clean(PRESETS['rf433'])
    link = RadioLink(params, random.Random(1), 0.0)
    assert link.next_event_s() is None
    link.send(TO_FISH, b'abc', 0.0)
    assert link.next_event_s() == pytest.approx(params.gather_s)
    link.poll(params.gather_s)
    due = link.next_event_s()
    assert due == pytest.approx(params.gather_s + params.air_time_s(3) + params.latency_s)
    assert link.poll(due - 1e-6) == []
    assert link.poll(due) == [(TO_FISH, b'abc')]


@pytest.mark.parametrize('change', [{'bit_rate_bps': 0.0}, {'loss_bad': 1.5},
                                    {'jitter_s': float('nan')}, {'buffer_bytes': 10},
                                    {'turnaround_s': -0.001}])
def test_impossible_numbers_are_refused(change):
    with pytest.raises(ValueError, match='radio wired'):
        replace(PRESETS['wired'], **change)


def test_an_unknown_preset_names_the_presets():
    with pytest.raises(ValueError, match='wired, bluetooth, rf433'):
        preset('wifi')


def test_the_presets_capacities():
    # What each preset carries one way in full packets (bytes/s): the figures of REFERENCE.md.
    assert PRESETS['wired'].capacity_bytes_s == pytest.approx(11520.0)
    assert PRESETS['bluetooth'].capacity_bytes_s == pytest.approx(11520.0)
    assert PRESETS['rf433'].capacity_bytes_s == pytest.approx(960.0)   # its UART binds
    assert clean(PRESETS['rf433']).capacity_bytes_s == pytest.approx(60 / (69 * 8 / 15000))


def test_frames_are_cut_at_their_boundaries():
    assert frame_units(b'\x00ab\x00\x00cd\x00') == [b'\x00ab\x00', b'\x00cd\x00']
    assert frame_units(b'raw bytes') == [b'raw bytes']


def test_the_uart_paces_the_bytes_and_refuses_whole_frames():
    params = replace(clean(PRESETS['rf433']), uart_baud=9600.0, uart_buffer_bytes=100)
    link = RadioLink(params, random.Random(1), 0.0)
    frame = b'\x00' + bytes(range(1, 59)) + b'\x00'          # 60 bytes
    heartbeat = b'\x00' + bytes(range(1, 13)) + b'\x00'      # 14 bytes
    link.send(TO_HOST, frame + frame + heartbeat, 0.0)       # the second frame does not fit
    assert link.stats.to_host.frames_refused == 1
    got = run(link, 1.0)
    assert b''.join(data for _, _, data in got) == frame + heartbeat
    # 74 bytes at 960 B/s reach the module after 77 ms; then the packet's air time.
    assert got[0][0] >= 60 / 960.0
